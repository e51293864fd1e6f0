// Python bindings of the textile C++ core (module textile._cpp).
// Thin: arrays in, arrays out; PETSc matrices through dolfinx's caster.
#include "../textile/assembly/absolute_product.h"
#include "../textile/assembly/beam_assembler.h"
#include "../textile/assembly/petsc_insert.h"
#include "../textile/assembly/petsc_error.h"
#include "../textile/assembly/sparsity_pattern.h"
#include "../textile/beam/beam_element.h"
#include "../textile/geometry_error.h"
#include "../textile/loads/end_moment.h"

#include "bindings.h"

#include <caster_petsc.h>
#include <petscsnes.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <optional>
#include <span>

namespace py = pybind11;
using namespace textile;

namespace
{
/// Writable span over a numpy array that must already be contiguous and of
/// the right dtype (no silent copy: results would be lost).
template <typename T>
std::span<T> wspan(py::array_t<T>& a, const char* name)
{
  if (!(a.flags() & py::array::c_style))
    throw std::invalid_argument(std::string(name) + " must be a C-contiguous array");
  return std::span<T>(a.mutable_data(), a.size());
}

template <typename T>
std::vector<T> to_vector(const carray<T>& a)
{
  return std::vector<T>(a.data(), a.data() + a.size());
}
} // namespace

PYBIND11_MODULE(_cpp, m)
{
  m.doc() = "textile C++ core: beam elements, loads, junctions and their PETSc assembly";

  // a state outside the model's domain (folded element, ...): the solver
  // cuts the step; any other exception is a bug and propagates
  py::register_exception<GeometryError>(m, "GeometryError", PyExc_RuntimeError);

  py::class_<beam::Material>(m, "Material")
      .def(py::init(
               [](double E, double nu)
               {
                 beam::Material mat{E, nu};
                 beam::validate(mat);
                 return mat;
               }),
           py::arg("young"), py::arg("poisson"))
      .def_readonly("young", &beam::Material::young)
      .def_readonly("poisson", &beam::Material::poisson)
      .def_property_readonly("shear_modulus", &beam::Material::shear_modulus);

  py::class_<beam::SectionQuadrature>(m, "SectionQuadrature")
      .def(py::init(&beam::disk_quadrature), py::arg("radius"), py::arg("order"))
      .def_readonly("radius", &beam::SectionQuadrature::radius)
      .def_readonly("order", &beam::SectionQuadrature::order)
      .def_property_readonly("points",
                             [](const beam::SectionQuadrature& q)
                             {
                               carray<double> p({q.size(), std::size_t(2)});
                               auto v = p.mutable_unchecked<2>();
                               for (std::size_t i = 0; i < q.size(); ++i)
                               {
                                 v(i, 0) = q.xi1[i];
                                 v(i, 1) = q.xi2[i];
                               }
                               return p;
                             })
      .def_property_readonly("weights", [](const beam::SectionQuadrature& q)
                             { return carray<double>(q.size(), q.weights.data()); });

  m.def(
      "gauss_legendre",
      [](int n)
      {
        auto r = beam::gauss_legendre(n);
        return py::make_tuple(carray<double>(n, r.points.data()),
                              carray<double>(n, r.weights.data()));
      },
      py::arg("n"));

  py::class_<beam::ElementRule>(m, "ElementRule")
      .def(py::init(
               [](int num_nodes, int axial_points, bool poisson_cure)
               {
                 if (num_nodes != 2 and num_nodes != 3)
                   throw std::invalid_argument("ElementRule: num_nodes must be 2 or 3");
                 return beam::ElementRule{num_nodes, beam::gauss_legendre(axial_points),
                                          poisson_cure};
               }),
           py::arg("num_nodes"), py::arg("axial_points"), py::arg("poisson_cure") = true)
      .def_readonly("num_nodes", &beam::ElementRule::num_nodes)
      .def_readonly("poisson_cure", &beam::ElementRule::poisson_cure)
      .def_property_readonly("axial_points",
                             [](const beam::ElementRule& r) { return r.axial.points.size(); });

  m.def(
      "element_residual_tangent",
      [](const beam::ElementRule& rule, const beam::Material& mat,
         const beam::SectionQuadrature& sec, const carray<double>& X, const carray<double>& x,
         const std::optional<carray<double>>& dx)
      {
        const std::size_t n = 9 * rule.num_nodes;
        carray<double> r(n), K({n, n});
        std::fill_n(r.mutable_data(), n, 0.0);
        std::fill_n(K.mutable_data(), n * n, 0.0);
        const double e = beam::element_residual_tangent(
            rule, mat, sec, cspan(X), cspan(x), std::span<double>(r.mutable_data(), n),
            std::span<double>(K.mutable_data(), n * n),
            dx ? cspan(*dx) : std::span<const double>());
        return py::make_tuple(e, r, K);
      },
      py::arg("rule"), py::arg("material"), py::arg("section"), py::arg("X"), py::arg("x"),
      py::arg("dx") = py::none(),
      "Energy, internal force and tangent of one element (positions, not displacements); "
      "with dx (the last Newton update) the MIP Newton tangent.");

  py::class_<assembly::BeamAssembler>(m, "BeamAssembler")
      .def(py::init(
               [](const beam::ElementRule& rule, const carray<std::int32_t>& conn,
                  const carray<std::int32_t>& groups, std::vector<beam::Material> mats,
                  std::vector<beam::SectionQuadrature> secs, const carray<double>& X,
                  const carray<std::int32_t>& numbers)
               {
                 return assembly::BeamAssembler(rule, to_vector(conn), to_vector(groups),
                                                std::move(mats), std::move(secs), to_vector(X),
                                                to_vector(numbers));
               }),
           py::arg("rule"), py::arg("connectivity"), py::arg("element_group"),
           py::arg("materials"), py::arg("sections"), py::arg("X"),
           py::arg("element_number") = carray<std::int32_t>(0),
           "element_number: each element's number within its fibre (error messages; "
           "default: the local element index)")
      .def_property_readonly("num_elements", &assembly::BeamAssembler::num_elements)
      .def_property("num_threads", &assembly::BeamAssembler::num_threads,
                    &assembly::BeamAssembler::set_num_threads,
                    "threads of the element loops (PETSc insertion stays serial)")
      .def(
          "assemble_vector",
          [](const assembly::BeamAssembler& self, const carray<double>& u, py::array_t<double>& b)
          { return self.assemble_vector(cspan(u), wspan(b, "b")); },
          py::arg("u"), py::arg("b"), "b += internal force; returns the stored energy")
      .def(
          "assemble_matrix",
          [](const assembly::BeamAssembler& self, Mat A, const carray<double>& u,
             const carray<std::int32_t>& dofs, const std::optional<carray<double>>& du,
             const std::optional<carray<double>>& du_weights)
          {
            self.assemble_matrix(A, cspan(u), cspan(dofs),
                                 du ? cspan(*du) : std::span<const double>(),
                                 du_weights ? cspan(*du_weights) : std::span<const double>());
          },
          py::arg("A"), py::arg("u"), py::arg("dofs"), py::arg("du") = py::none(),
          py::arg("du_weights") = py::none(),
          "A += tangent; with du (the last Newton update, 9 per local node) the MIP Newton "
          "tangent; du may hold k updates one after another (k x 9 per local node), "
          "weighted by du_weights (k values; None: 1)")
      .def(
          "fields",
          [](const assembly::BeamAssembler& self, const carray<double>& u)
          {
            auto f = self.fields(cspan(u));
            carray<double> out({f.size() / 12, std::size_t(12)});
            std::copy(f.begin(), f.end(), out.mutable_data());
            return out;
          },
          py::arg("u"));

  m.def(
      "end_moment",
      [](const carray<double>& M, const carray<double>& g)
      {
        carray<double> f(6), J({6, 6});
        loads::end_moment(cspan(M), cspan(g), std::span<double>(f.mutable_data(), 6),
                          std::span<double>(J.mutable_data(), 36));
        return py::make_tuple(f, J);
      },
      py::arg("M"), py::arg("g"),
      "Generalized forces on [g1, g2] applying moment M, and their derivative.");

  m.def(
      "add_block",
      [](Mat A, const carray<std::int32_t>& rows, const carray<std::int32_t>& cols,
         const carray<double>& values) { assembly::add_block(A, cspan(rows), cspan(cols), cspan(values)); },
      py::arg("A"), py::arg("rows"), py::arg("cols"), py::arg("values"),
      "A[rows, cols] += values (local numbering; negative indices skipped)");

  m.def(
      "add_entries",
      [](Mat A, const carray<std::int32_t>& rows, const carray<std::int32_t>& cols,
         const carray<double>& values)
      { assembly::add_entries(A, cspan(rows), cspan(cols), cspan(values)); },
      py::arg("A"), py::arg("rows"), py::arg("cols"), py::arg("values"),
      "A[rows[k], cols[k]] += values[k] (local numbering; negative indices skipped)");

  m.def(
      "add_diagonal",
      [](Mat A, const carray<std::int32_t>& rows, double value)
      { assembly::add_diagonal(A, cspan(rows), value); },
      py::arg("A"), py::arg("rows"), py::arg("value"), "A[i, i] += value for i in rows (local)");

  m.def(
      "nonzero_state",
      [](Mat A)
      {
        PetscObjectState state;
        assembly::check(MatGetNonzeroState(A, &state), "MatGetNonzeroState");
        return static_cast<long long>(state);
      },
      py::arg("A"), "PETSc's counter of A's nonzero pattern: it changes when the pattern does");

  py::class_<assembly::SparsityPattern>(m, "SparsityPattern")
      .def(py::init<Mat>(), py::arg("base"),
           "The pattern of base (assembled AIJ), to which rebuilt matrices add entries")
      .def(
          "add",
          [](assembly::SparsityPattern& self, const carray<std::int32_t>& rows,
             const carray<std::int32_t>& cols) { self.add(cspan(rows), cspan(cols)); },
          py::arg("rows"), py::arg("cols"),
          "Declare the block [rows, cols] (global indices, negative skipped, any rank's rows)")
      .def("create_matrix", &assembly::SparsityPattern::create_matrix, py::arg("base"),
           py::return_value_policy::take_ownership,
           "New assembled zero matrix: base's pattern as read, base's layout and maps, plus "
           "the declared entries, which are then forgotten (collective)")
      .def_property_readonly("base_size", &assembly::SparsityPattern::base_size);

  m.def("absolute_product", &assembly::absolute_product, py::arg("A"), py::arg("x"),
        py::arg("y"), "y = |A| |x| (entrywise absolute values; assembled AIJ matrix)");

  m.def(
      "set_lag_preconditioner",
      [](SNES snes, int lag)
      { assembly::check(SNESSetLagPreconditioner(snes, lag), "SNESSetLagPreconditioner"); },
      py::arg("snes"), py::arg("lag"),
      "SNESSetLagPreconditioner (petsc4py 3.18 has no binding): -2 refactorizes at the "
      "tangent being assembled, -1 keeps the last factorization; read after the Jacobian "
      "callback, so the callback may set it");

  m.def(
      "set_diagonal_scale",
      [](KSP ksp, bool on)
      {
        const PetscBool flag = on ? PETSC_TRUE : PETSC_FALSE;
        assembly::check(KSPSetDiagonalScale(ksp, flag), "KSPSetDiagonalScale");
        assembly::check(KSPSetDiagonalScaleFix(ksp, flag), "KSPSetDiagonalScaleFix");
      },
      py::arg("ksp"), py::arg("on"),
      "KSPSetDiagonalScale and KSPSetDiagonalScaleFix (petsc4py 3.18 has no binding): solve "
      "D A D y = D b, x = D y with D = |diag A|^(-1/2) (1 where the diagonal is 0), A "
      "scaled back after each solve");

  declare_contact(m);
  declare_rigid(m);
  declare_junction(m);
}
