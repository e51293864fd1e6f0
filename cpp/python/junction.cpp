// Bindings of the fibre-matrix junctions (cpp/textile/junction/).
#include "../textile/junction/fibre_matrix_junction.h"
#include "../textile/junction/junction_set.h"

#include "bindings.h"

#include <caster_petsc.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <string>

namespace py = pybind11;
using namespace textile;

namespace
{
template <typename T>
std::vector<T> vec(const carray<T>& a)
{
  return std::vector<T>(a.data(), a.data() + a.size());
}

std::span<double> out_span(py::array_t<double>& a, const char* name)
{
  if (!(a.flags() & py::array::c_style))
    throw std::invalid_argument(std::string(name) + " must be a C-contiguous array");
  return std::span<double>(a.mutable_data(), a.size());
}

carray<double> as_rows(const std::vector<double>& v)
{
  carray<double> out({v.size() / 3, std::size_t(3)});
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}
} // namespace

void declare_junction(py::module_& m)
{
  m.def(
      "fibre_matrix_junction",
      [](double k, double w, int num_fibre_nodes, double xi, const carray<double>& X_f,
         const carray<double>& u_f, const carray<double>& X_m, const carray<double>& phi,
         const carray<double>& u_m, double c1, double c2)
      {
        const std::size_t n = 9 * num_fibre_nodes + 3 * phi.size();
        const double c[2] = {c1, c2};
        carray<double> gap(3), r(n), K({n, n});
        std::fill_n(r.mutable_data(), n, 0.0);
        std::fill_n(K.mutable_data(), n * n, 0.0);
        const double e = junction::fibre_matrix_junction(
            k, w, num_fibre_nodes, xi, std::span<const double>(c, 2), cspan(X_f), cspan(u_f), cspan(X_m), cspan(phi), cspan(u_m),
            std::span<double>(gap.mutable_data(), 3), std::span<double>(r.mutable_data(), n),
            std::span<double>(K.mutable_data(), n * n));
        return py::make_tuple(e, gap, r, K);
      },
      py::arg("k"), py::arg("w"), py::arg("num_fibre_nodes"), py::arg("xi"), py::arg("X_f"),
      py::arg("u_f"), py::arg("X_m"), py::arg("phi"), py::arg("u_m"), py::arg("c1") = 0.0,
      py::arg("c2") = 0.0,
      "One junction of the particle at section coordinates (c1, c2): (energy, gap, residual, "
      "tangent); X_f, u_f 9 per fibre node (x0, g1, g2); residual order [fibre nodes (9 "
      "each), matrix nodes (3 each)]");

  py::class_<junction::JunctionSet>(m, "JunctionSet")
      .def(py::init(
               [](double k, int nf, const carray<std::int32_t>& elem, const carray<double>& xi,
                  const carray<double>& section, const carray<double>& w, const carray<double>& Xf, const carray<double>& Xm,
                  const carray<std::int32_t>& cells, const carray<double>& phi)
               {
                 return junction::JunctionSet(k, nf, vec(elem), vec(xi), vec(section), vec(w), vec(Xf),
                                              vec(Xm), vec(cells), vec(phi));
               }),
           py::arg("k"), py::arg("num_fibre_nodes"), py::arg("element_nodes"), py::arg("xi"),
           py::arg("section"), py::arg("weight"), py::arg("X_fibre"), py::arg("X_matrix"), py::arg("cell_nodes"),
           py::arg("phi"))
      .def_property_readonly("size", &junction::JunctionSet::size)
      .def_property_readonly("num_blocks", &junction::JunctionSet::num_blocks)
      .def_property_readonly("num_cell_nodes", &junction::JunctionSet::num_cell_nodes)
      .def_property_readonly("stiffness", &junction::JunctionSet::stiffness)
      .def(
          "assemble_vector",
          [](const junction::JunctionSet& self, const carray<double>& uf,
             const carray<double>& um, py::array_t<double>& bf, py::array_t<double>& bm)
          { return self.assemble_vector(cspan(uf), cspan(um), out_span(bf, "b_fibre"),
                                        out_span(bm, "b_matrix")); },
          py::arg("u_fibre"), py::arg("u_matrix"), py::arg("b_fibre"), py::arg("b_matrix"),
          "b += residual; returns the stored energy")
      .def(
          "assemble_matrix",
          [](junction::JunctionSet& self, Mat A, const carray<std::int32_t>& df,
             const carray<std::int32_t>& dm) { self.assemble_matrix(A, cspan(df), cspan(dm)); },
          py::arg("A"), py::arg("dofs_fibre"), py::arg("dofs_matrix"))
      .def(
          "gaps", [](const junction::JunctionSet& self, const carray<double>& uf,
                     const carray<double>& um) { return as_rows(self.gaps(cspan(uf), cspan(um))); },
          py::arg("u_fibre"), py::arg("u_matrix"), "(n, 3) x_f - x_m")
      .def(
          "forces", [](const junction::JunctionSet& self, const carray<double>& uf,
                       const carray<double>& um)
          { return as_rows(self.forces(cspan(uf), cspan(um))); },
          py::arg("u_fibre"), py::arg("u_matrix"), "(n, 3) force on the matrix, k w gap")
      .def(
          "total_force",
          [](const junction::JunctionSet& self, const carray<double>& uf, const carray<double>& um)
          {
            const auto f = self.total_force(cspan(uf), cspan(um));
            return carray<double>(3, f.data());
          },
          py::arg("u_fibre"), py::arg("u_matrix"));
}
