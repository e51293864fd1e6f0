// Python bindings of contact detection and the contact set.
#include "bindings.h"

#include "../textile/contact/contact_normal.h"
#include "../textile/contact/detection.h"

#include <caster_petsc.h>
#include <pybind11/stl.h>

#include <cmath>

namespace py = pybind11;
using namespace textile;
using namespace textile::contact;

namespace
{
carray<double> rows3(const std::vector<Eigen::Vector3d>& v)
{
  carray<double> out({v.size(), std::size_t(3)});
  auto a = out.mutable_unchecked<2>();
  for (std::size_t i = 0; i < v.size(); ++i)
    for (int k = 0; k < 3; ++k)
      a(i, k) = v[i](k);
  return out;
}

template <typename T>
carray<T> array_of(const std::vector<T>& v)
{
  carray<T> out(v.size());
  std::copy(v.begin(), v.end(), out.mutable_data());
  return out;
}

Eigen::Vector3d row(const carray<double>& a, std::size_t i)
{
  return Eigen::Vector3d(a.data()[3 * i], a.data()[3 * i + 1], a.data()[3 * i + 2]);
}

/// Centre lines and section vectors from the (nodes, 9) array q.
struct Geometry
{
  Centrelines lines;
  std::vector<double> g;
  Geometry(const carray<double>& q, const carray<std::int64_t>& first_node, int order,
           const carray<double>& radius)
  {
    const std::size_t n = q.size() / 9;
    lines.x.resize(3 * n);
    g.resize(6 * n);
    for (std::size_t i = 0; i < n; ++i)
      for (int k = 0; k < 3; ++k)
      {
        lines.x[3 * i + k] = q.data()[9 * i + k];
        g[6 * i + k] = q.data()[9 * i + 3 + k];
        g[6 * i + 3 + k] = q.data()[9 * i + 6 + k];
      }
    lines.fibre_offsets.assign(first_node.data(), first_node.data() + first_node.size());
    lines.order = order;
    lines.radius.assign(radius.data(), radius.data() + radius.size());
  }
};
} // namespace

void declare_contact(py::module_& m)
{
  m.def(
      "detect_contacts",
      [](const carray<double>& q, const carray<std::int64_t>& first_node, int order,
         const carray<double>& radius, double delta_factor, double self_exclusion, double spacing,
         double parallel_angle)
      {
        Geometry geo(q, first_node, order, radius);
        const SectionVectors g{geo.g};
        const Detection d = detect(geo.lines, g, delta_factor, self_exclusion, spacing, parallel_angle);
        const std::size_t n = d.points.size();
        std::vector<int> fi(n), fj(n);
        std::vector<double> si(n), sj(n), par(n), a1(n), a2(n), b1(n), b2(n), len(n);
        std::vector<int> crossing(n);
        std::vector<Eigen::Vector3d> ti(n), tj(n), t(n), gap(n);
        for (std::size_t k = 0; k < n; ++k)
        {
          const auto& p = d.points[k];
          fi[k] = p.fibre_i;
          fj[k] = p.fibre_j;
          si[k] = p.s_i;
          sj[k] = p.s_j;
          par[k] = p.parameter;
          len[k] = p.length;
          crossing[k] = p.crossing;
          a1[k] = p.xi1_i;
          a2[k] = p.xi2_i;
          b1[k] = p.xi1_j;
          b2[k] = p.xi2_j;
          ti[k] = p.tangent_i;
          tj[k] = p.tangent_j;
          t[k] = p.tangent;
          gap[k] = p.centroid_gap;
        }
        py::dict out;
        out["zone"] = array_of(d.zone_of_point);
        out["fibre_i"] = array_of(fi);
        out["fibre_j"] = array_of(fj);
        out["s_i"] = array_of(si);
        out["s_j"] = array_of(sj);
        out["parameter"] = array_of(par);
        out["length"] = array_of(len);
        out["crossing"] = array_of(crossing);
        out["xi1_i"] = array_of(a1);
        out["xi2_i"] = array_of(a2);
        out["xi1_j"] = array_of(b1);
        out["xi2_j"] = array_of(b2);
        out["tangent_i"] = rows3(ti);
        out["tangent_j"] = rows3(tj);
        out["tangent"] = rows3(t);
        out["centroid_gap"] = rows3(gap);
        out["num_zones"] = d.zones.size();
        return out;
      },
      py::arg("q"), py::arg("first_node"), py::arg("order"), py::arg("radius"),
      py::arg("delta_factor"), py::arg("self_exclusion"), py::arg("spacing"),
      py::arg("parallel_angle"),
      "One detection pass on the current nodal unknowns q (nodes x 9): proximity zones and "
      "contact points on their intermediate geometries (dict of arrays).");

  m.def(
      "contact_normals",
      [](const carray<double>& ti, const carray<double>& tj, const carray<double>& t,
         const carray<double>& gap, const carray<double>& previous, double parallel_angle)
      {
        const std::size_t n = ti.size() / 3;
        std::vector<Eigen::Vector3d> out(n);
        for (std::size_t k = 0; k < n; ++k)
          out[k] = contact_normal(row(ti, k), row(tj, k), row(t, k), row(gap, k),
                                  row(previous, k), parallel_angle);
        return rows3(out);
      },
      py::arg("tangent_i"), py::arg("tangent_j"), py::arg("tangent"), py::arg("centroid_gap"),
      py::arg("previous"), py::arg("parallel_angle"));

  py::class_<ContactSet>(m, "ContactSet")
      .def(py::init<>())
      .def("copy", [](const ContactSet& self) { return ContactSet(self); })
      .def_property_readonly("size", [](const ContactSet& self) { return self.elements.size(); })
      .def(
          "set_elements",
          [](ContactSet& self, py::dict found, const carray<double>& normals,
             const carray<double>& penalty, double g_r, double mu, double u_rev,
             const carray<double>& elastic_slip, const carray<double>& q,
             const carray<std::int64_t>& first_node, int order, const carray<double>& radius,
             std::pair<std::int64_t, std::int64_t> owned)
          {
            // rebuild the points from the arrays of detect_contacts
            Geometry geo(q, first_node, order, radius);
            auto get = [&](const char* k) { return found[k].cast<carray<double>>(); };
            auto geti = [&](const char* k) { return found[k].cast<carray<int>>(); };
            const auto fi = geti("fibre_i"), fj = geti("fibre_j"), zone = geti("zone"),
                       crossing = geti("crossing");
            const auto si = get("s_i"), sj = get("s_j"), a1 = get("xi1_i"), a2 = get("xi2_i"),
                       b1 = get("xi1_j"), b2 = get("xi2_j"), len = get("length");
            const RegularizedCoulomb fr{mu, u_rev};
            self.elements.clear();
            for (py::ssize_t k = 0; k < fi.size(); ++k)
            {
              ContactPoint p;
              p.fibre_i = fi.data()[k];
              p.fibre_j = fj.data()[k];
              p.s_i = si.data()[k];
              p.s_j = sj.data()[k];
              p.xi1_i = a1.data()[k];
              p.xi2_i = a2.data()[k];
              p.xi1_j = b1.data()[k];
              p.xi2_j = b2.data()[k];
              p.length = len.data()[k];
              p.crossing = crossing.data()[k] != 0;
              auto e = make_element(geo.lines, p, zone.data()[k], row(normals, k),
                                    penalty.data()[k], g_r, fr, row(elastic_slip, k),
                                    std::span<const double>(q.data(), q.size()));
              // each element is evaluated by the rank owning its first node on fibre i
              if (e.nodes_i[0] >= owned.first and e.nodes_i[0] < owned.second)
                self.elements.push_back(e);
            }
          },
          py::arg("found"), py::arg("normals"), py::arg("penalty"), py::arg("g_r"), py::arg("mu"),
          py::arg("u_rev"), py::arg("elastic_slip"), py::arg("q"), py::arg("first_node"),
          py::arg("order"), py::arg("radius"), py::arg("owned"))
      .def("set_penalties",
           [](ContactSet& self, const carray<double>& k)
           {
             for (std::size_t i = 0; i < self.elements.size(); ++i)
               self.elements[i].penalty = k.data()[i];
           })
      .def("evaluate", [](ContactSet& self, const carray<double>& q)
           { self.evaluate(std::span<const double>(q.data(), q.size())); })
      .def("assemble_vector",
           [](ContactSet& self, const carray<double>& q, const carray<std::int32_t>& dofs, Vec b)
           { self.assemble_vector(cspan(q), cspan(dofs), b); })
      .def("assemble_matrix",
           [](const ContactSet& self, const carray<double>& q, const carray<std::int32_t>& dofs,
              Mat A) { self.assemble_matrix(cspan(q), cspan(dofs), A); })
      .def("nodal_forces",
           [](const ContactSet& self, const carray<double>& q)
           { return array_of(self.nodal_forces(cspan(q))); })
      .def("insert_pattern",
           [](const ContactSet& self, Mat P, const carray<std::int32_t>& dofs, double margin)
           { self.insert_pattern(P, cspan(dofs), margin); },
           py::arg("P"), py::arg("dofs"), py::arg("margin"))
      .def("commit", &ContactSet::commit)
      .def_property_readonly("num_friction_histories", &ContactSet::num_friction_histories)
      .def("data",
           [](const ContactSet& self)
           {
             const std::size_t n = self.elements.size();
             std::vector<int> fi(n), fj(n), zone(n);
             std::vector<double> si(n), sj(n), k(n), gap(n), RN(n), len(n);
             std::vector<bool> slip(n);
             std::vector<Eigen::Vector3d> N(n), T(n), el(n), xi(n), xj(n);
             for (std::size_t i = 0; i < n; ++i)
             {
               const auto& e = self.elements[i];
               fi[i] = e.fibre_i;
               fj[i] = e.fibre_j;
               zone[i] = e.zone;
               si[i] = e.s_i;
               sj[i] = e.s_j;
               k[i] = e.penalty;
               len[i] = e.length;
               gap[i] = e.result.gap;
               RN[i] = e.result.normal_force;
               slip[i] = e.result.slip;
               N[i] = e.normal;
               T[i] = e.result.tangential_force;
               el[i] = self.elastic_slip(e);
               xi[i] = e.result.position_i;
               xj[i] = e.result.position_j;
             }
             py::dict out;
             out["fibre_i"] = array_of(fi);
             out["fibre_j"] = array_of(fj);
             out["zone"] = array_of(zone);
             out["s_i"] = array_of(si);
             out["s_j"] = array_of(sj);
             out["penalty"] = array_of(k);
             out["length"] = array_of(len);
             out["gap"] = array_of(gap);
             out["normal_force"] = array_of(RN);
             carray<bool> sl(n);
             for (std::size_t i = 0; i < n; ++i)
               sl.mutable_data()[i] = slip[i];
             out["slip"] = sl;
             out["normal"] = rows3(N);
             out["tangential_force"] = rows3(T);
             out["elastic_slip"] = rows3(el);
             out["position_i"] = rows3(xi);
             out["position_j"] = rows3(xj);
             return out;
           });
}
