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
             const carray<double>& offset, const carray<double>& g1, const carray<double>& g2,
             const carray<double>& scale_position, const carray<double>& scale_section)
          {
            self.couplings.resize(body.size());
            for (py::ssize_t i = 0; i < body.size(); ++i)
            {
              auto& c = self.couplings[i];
              c.body = body.data()[i];
              c.node = node.data()[i];
              c.multiplier = multiplier.data()[i];
              c.base.section = section.data()[i];
              c.base.offset = vec3(offset, i);
              c.base.g1 = vec3(g1, i);
              c.base.g2 = vec3(g2, i);
              c.scale_position = scale_position.data()[i];
              c.scale_section = scale_section.data()[i];
            }
          },
          py::arg("body"), py::arg("node"), py::arg("multiplier"), py::arg("section"),
          py::arg("offset"), py::arg("g1"), py::arg("g2"), py::arg("scale_position"),
          py::arg("scale_section"))
      .def(
          "assemble_vector",
          [](const RigidBodySet& self, const carray<double>& X, const carray<double>& u,
             const carray<double>& w, const carray<double>& lam, py::array_t<double>& b_fibre,
             py::array_t<double>& b_body, py::array_t<double>& b_lambda)
          {
            self.assemble_vector(cspan(X), cspan(u), cspan(w), cspan(lam), out_span(b_fibre),
                                 out_span(b_body), out_span(b_lambda));
          },
          py::arg("X"), py::arg("u_fibre"), py::arg("u_body"), py::arg("multipliers"),
          py::arg("b_fibre"), py::arg("b_body"), py::arg("b_multipliers"))
      .def(
          "assemble_matrix",
          [](const RigidBodySet& self, Mat A, const carray<double>& X, const carray<double>& u,
             const carray<double>& w, const carray<double>& lam,
             const carray<std::int32_t>& dofs_fibre, const carray<std::int32_t>& dofs_body,
             const carray<std::int32_t>& dofs_lambda)
          {
            self.assemble_matrix(A, cspan(X), cspan(u), cspan(w), cspan(lam),
                                 cspan(dofs_fibre), cspan(dofs_body), cspan(dofs_lambda));
          },
          py::arg("A"), py::arg("X"), py::arg("u_fibre"), py::arg("u_body"),
          py::arg("multipliers"), py::arg("dofs_fibre"), py::arg("dofs_body"),
          py::arg("dofs_multipliers"))
      .def(
          "reactions",
          [](const RigidBodySet& self, const carray<double>& X, const carray<double>& u,
             const carray<double>& w, const carray<double>& lam)
          {
            const auto r = self.reactions(cspan(X), cspan(u), cspan(w), cspan(lam));
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
          "(bodies, 6): force and moment (about the current centre) each body exerts on what "
          "it holds, from this rank's couplings")
      .def_property_readonly("has_moments", &RigidBodySet::has_moments);
}
