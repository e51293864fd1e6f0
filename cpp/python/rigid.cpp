// Python bindings of the rigid bodies (textile/effects/rigid_bodies.py).
#include "bindings.h"

#include "../textile/rigid/rigid_body_set.h"
#include "../textile/rigid/rotation.h"

#include <caster_petsc.h>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace textile::rigid;

namespace
{
Eigen::Vector3d vec3(const carray<double>& a, std::size_t i)
{
  return Eigen::Vector3d(a.data() + 3 * i);
}

template <typename T>
std::span<T> out_span(py::array_t<T>& a)
{
  if (!(a.flags() & py::array::c_style))
    throw std::invalid_argument("output arrays must be C-contiguous");
  return std::span<T>(a.mutable_data(), a.size());
}
} // namespace

void declare_rigid(py::module_& m)
{
  m.def(
      "rotation_matrix",
      [](const carray<double>& theta)
      {
        const Eigen::Matrix3d R = rotation_matrix(vec3(theta, 0));
        carray<double> out({3, 3});
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            out.mutable_data()[3 * i + j] = R(i, j);
        return out;
      },
      py::arg("theta"), "exp([theta]) (3 x 3)");

  py::class_<RigidBodySet>(m, "RigidBodySet")
      .def(py::init<>())
      .def(
          "set_centres",
          [](RigidBodySet& self, const carray<double>& centres)
          {
            self.centres.resize(centres.size() / 3);
            for (std::size_t b = 0; b < self.centres.size(); ++b)
              self.centres[b] = vec3(centres, b);
          },
          py::arg("centres"), "Reference centres of all local bodies")
      .def(
          "set_loads",
          [](RigidBodySet& self, const carray<double>& forces, const carray<double>& moments)
          {
            self.forces.clear();
            self.moments.clear();
            for (std::size_t b = 0; b < forces.size() / 3; ++b)
            {
              self.forces.push_back(vec3(forces, b));
              self.moments.push_back(vec3(moments, b));
            }
          },
          py::arg("forces"), py::arg("moments"),
          "Current body loads, only where the bodies are owned (empty elsewhere)")
      .def(
          "set_couplings",
          [](RigidBodySet& self, const carray<int>& body, const carray<std::int32_t>& node,
             const carray<std::int32_t>& multiplier, const carray<bool>& section,
             const carray<bool>& block, const carray<double>& offset, const carray<double>& g1,
             const carray<double>& g2, const carray<double>& scale_position,
             const carray<double>& scale_section, const carray<std::int32_t>& sliding_rows,
             const carray<std::int32_t>& row_vector, const carray<double>& row_direction)
          {
            const py::ssize_t n = body.size();
            if (node.size() != n or multiplier.size() != n or section.size() != n
                or block.size() != n or offset.size() != 3 * n or g1.size() != 3 * n
                or g2.size() != 3 * n or scale_position.size() != n
                or scale_section.size() != n or sliding_rows.size() != n
                or row_direction.size() != 3 * row_vector.size())
              throw std::invalid_argument("set_couplings: inconsistent array sizes");
            self.couplings.resize(n);
            py::ssize_t row = 0; // next sliding row
            for (py::ssize_t i = 0; i < n; ++i)
            {
              auto& c = self.couplings[i];
              c.body = body.data()[i];
              c.node = node.data()[i];
              c.multiplier = multiplier.data()[i];
              c.holds = block.data()[i] ? Holds::block : Holds::fibre;
              c.base.section = section.data()[i] and !block.data()[i];
              c.base.offset = vec3(offset, i);
              c.base.g1 = vec3(g1, i);
              c.base.g2 = vec3(g2, i);
              c.scale_position = scale_position.data()[i];
              c.scale_section = scale_section.data()[i];
              c.sliding.resize(sliding_rows.data()[i]);
              for (auto& r : c.sliding)
              {
                if (row >= row_vector.size())
                  throw std::invalid_argument("set_couplings: too few sliding rows");
                r.vector = row_vector.data()[row];
                r.direction = vec3(row_direction, row);
                ++row;
              }
            }
            if (row != row_vector.size())
              throw std::invalid_argument("set_couplings: too many sliding rows");
          },
          py::arg("body"), py::arg("node"), py::arg("multiplier"), py::arg("section"),
          py::arg("block"), py::arg("offset"), py::arg("g1"), py::arg("g2"),
          py::arg("scale_position"), py::arg("scale_section"), py::arg("sliding_rows"),
          py::arg("row_vector"), py::arg("row_direction"),
          "All couplings of this rank: per coupling its body, local node (fibre node, or "
          "block node where block is true), first multiplier row, section (fibre sections: "
          "9 unknowns), offset/g1/g2 in the body frame, row scales, and its number of "
          "sliding rows (0: fully held), whose held vector (0 x0, 1 g1, 2 g2) and direction "
          "follow in row_vector/row_direction, coupling after coupling")
      .def(
          "assemble_vector",
          [](const RigidBodySet& self, const carray<double>& X, const carray<double>& u,
             const carray<double>& w, const carray<double>& lam, const carray<double>& X_block,
             const carray<double>& u_block, py::array_t<double>& b_fibre,
             py::array_t<double>& b_body, py::array_t<double>& b_lambda,
             py::array_t<double>& b_block)
          {
            self.assemble_vector(cspan(X), cspan(u), cspan(w), cspan(lam),
                                 BlockArrays{cspan(X_block), cspan(u_block)}, out_span(b_fibre),
                                 out_span(b_body), out_span(b_lambda), out_span(b_block));
          },
          py::arg("X"), py::arg("u_fibre"), py::arg("u_body"), py::arg("multipliers"),
          py::arg("X_block"), py::arg("u_block"), py::arg("b_fibre"), py::arg("b_body"),
          py::arg("b_multipliers"), py::arg("b_block"))
      .def(
          "assemble_matrix",
          [](const RigidBodySet& self, Mat A, const carray<double>& X, const carray<double>& u,
             const carray<double>& w, const carray<double>& lam, const carray<double>& X_block,
             const carray<double>& u_block, const carray<std::int32_t>& dofs_fibre,
             const carray<std::int32_t>& dofs_body, const carray<std::int32_t>& dofs_lambda,
             const carray<std::int32_t>& dofs_block)
          {
            self.assemble_matrix(A, cspan(X), cspan(u), cspan(w), cspan(lam),
                                 BlockArrays{cspan(X_block), cspan(u_block)}, cspan(dofs_fibre),
                                 cspan(dofs_body), cspan(dofs_lambda), cspan(dofs_block));
          },
          py::arg("A"), py::arg("X"), py::arg("u_fibre"), py::arg("u_body"),
          py::arg("multipliers"), py::arg("X_block"), py::arg("u_block"),
          py::arg("dofs_fibre"), py::arg("dofs_body"), py::arg("dofs_multipliers"),
          py::arg("dofs_block"))
      .def(
          "reactions",
          [](const RigidBodySet& self, const carray<double>& X, const carray<double>& u,
             const carray<double>& w, const carray<double>& lam, const carray<double>& X_block,
             const carray<double>& u_block)
          {
            const auto r = self.reactions(cspan(X), cspan(u), cspan(w), cspan(lam),
                                          BlockArrays{cspan(X_block), cspan(u_block)});
            carray<double> out({r.size(), std::size_t(6)});
            for (std::size_t b = 0; b < r.size(); ++b)
              for (int k = 0; k < 3; ++k)
              {
                out.mutable_data()[6 * b + k] = r[b].force(k);
                out.mutable_data()[6 * b + 3 + k] = r[b].moment(k);
              }
            return out;
          },
          py::arg("X"), py::arg("u_fibre"), py::arg("u_body"), py::arg("multipliers"),
          py::arg("X_block"), py::arg("u_block"),
          "(bodies, 6): force and moment (about the current centre) each body exerts on what "
          "it holds, from this rank's couplings")
      .def_property_readonly("has_moments", &RigidBodySet::has_moments);
}
