// Python bindings of contact detection and the contact set.
#include "bindings.h"

#include "../textile/contact/coupling_pattern.h"
#include "../textile/contact/detection.h"
#include "../textile/contact/held_contact.h"
#include "../textile/contact/history_handover.h"
#include "../textile/contact/history_transfer.h"
#include "../textile/contact/penalty_adaptation.h"

#include <caster_petsc.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <string>
#include <stdexcept>
#include <type_traits>

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

/// A per-zone rule (penalty, largest penetration) -> penalty, applied to
/// arrays of zones.
auto over_zones(double (PenaltyAdaptation::*rule)(double, double) const)
{
  return [rule](const PenaltyAdaptation& a, const carray<double>& k, const carray<double>& p)
  {
    if (k.size() != p.size())
      throw std::invalid_argument("PenaltyAdaptation: one penetration per penalty");
    carray<double> out(k.size());
    for (py::ssize_t z = 0; z < k.size(); ++z)
      out.mutable_data()[z] = (a.*rule)(k.data()[z], p.data()[z]);
    return out;
  };
}

/// One column of a table: get(item) for every item, as an array (n x 3
/// for 3-vectors).
template <typename Item, typename Get>
py::array column(const std::vector<Item>& items, Get get)
{
  using T = std::decay_t<std::invoke_result_t<Get, const Item&>>;
  if constexpr (std::is_same_v<T, Eigen::Vector3d>)
  {
    std::vector<Eigen::Vector3d> v;
    v.reserve(items.size());
    for (const auto& item : items)
      v.push_back(get(item));
    return rows3(v);
  }
  else
  {
    carray<T> out(items.size());
    for (std::size_t i = 0; i < items.size(); ++i)
      out.mutable_data()[i] = get(items[i]);
    return out;
  }
}

/// Held contacts (held_contact.h) as a dict of arrays, and back.
py::dict held_to_arrays(const std::vector<HeldContact>& held)
{
  py::dict out;
  out["fibre_i"] = column(held, [](const HeldContact& h) { return h.fibre_i; });
  out["fibre_j"] = column(held, [](const HeldContact& h) { return h.fibre_j; });
  out["s_i"] = column(held, [](const HeldContact& h) { return h.s_i; });
  out["s_j"] = column(held, [](const HeldContact& h) { return h.s_j; });
  out["normal"] = column(held, [](const HeldContact& h) { return h.normal; });
  out["length"] = column(held, [](const HeldContact& h) { return h.length; });
  out["crossing"] = column(held, [](const HeldContact& h) { return h.crossing; });
  return out;
}

std::vector<HeldContact> held_from_arrays(const py::dict& a)
{
  const auto fi = a["fibre_i"].cast<carray<int>>(), fj = a["fibre_j"].cast<carray<int>>();
  const auto si = a["s_i"].cast<carray<double>>(), sj = a["s_j"].cast<carray<double>>();
  const auto n = a["normal"].cast<carray<double>>(), len = a["length"].cast<carray<double>>();
  const auto cr = a["crossing"].cast<carray<bool>>();
  const auto size = static_cast<std::size_t>(fi.size());
  if (fj.size() != fi.size() or si.size() != fi.size() or sj.size() != fi.size()
      or n.size() != 3 * fi.size() or len.size() != fi.size() or cr.size() != fi.size())
    throw std::invalid_argument("held contacts: arrays of different lengths");
  std::vector<HeldContact> out(size);
  for (std::size_t k = 0; k < size; ++k)
    out[k] = {fi.data()[k], fj.data()[k], si.data()[k], sj.data()[k],
              Eigen::Vector3d(n.data() + 3 * k), len.data()[k], cr.data()[k]};
  return out;
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

/// mu for every pair, or group_mu[g] between two fibres of group g
/// (`group`: None, or one integer per fibre, -1 for none).
FrictionCoefficients friction_coefficients(double mu, const py::object& group,
                                           const py::object& group_mu, py::ssize_t num_fibres)
{
  FrictionCoefficients out{mu, {}, {}};
  if (group.is_none())
    return out;
  const auto g = group.cast<carray<int>>();
  const auto w = group_mu.cast<carray<double>>();
  if (g.size() != num_fibres)
    throw std::invalid_argument("friction groups: one group per fibre");
  for (py::ssize_t k = 0; k < g.size(); ++k)
    if (g.data()[k] >= w.size())
      throw std::invalid_argument("friction groups: a group without its coefficient");
  for (py::ssize_t k = 0; k < w.size(); ++k)
    if (!(w.data()[k] >= 0))
      throw std::invalid_argument("friction groups: coefficients must be >= 0");
  out.group.assign(g.data(), g.data() + g.size());
  out.within.assign(w.data(), w.data() + w.size());
  return out;
}
} // namespace

void declare_contact(py::module_& m)
{
  py::class_<Detection>(m, "Detection",
                        "One detection pass: proximity zones and the contact points on their "
                        "intermediate geometries (on several ranks, among the fibres a rank holds).")
      .def_property_readonly("num_zones", [](const Detection& d) { return d.zones.size(); })
      .def_property_readonly("size", [](const Detection& d) { return d.points.size(); })
      .def_property_readonly(
          "held", [](const Detection& d) { return d.held_source.size(); },
          "Points added for held contacts (one a held zone).")
      .def(
          "arrays",
          [](const Detection& d)
          {
            py::dict out;
            auto put = [&](const char* name, auto get) { out[name] = column(d.points, get); };
            out["zone"] = array_of(d.zone_of_point);
            put("fibre_i", [](const ContactPoint& p) { return p.fibre_i; });
            put("fibre_j", [](const ContactPoint& p) { return p.fibre_j; });
            put("s_i", [](const ContactPoint& p) { return p.s_i; });
            put("s_j", [](const ContactPoint& p) { return p.s_j; });
            put("parameter", [](const ContactPoint& p) { return p.parameter; });
            put("length", [](const ContactPoint& p) { return p.length; });
            put("crossing", [](const ContactPoint& p) { return p.crossing; });
            put("tangent", [](const ContactPoint& p) { return p.tangent; });
            put("centroid_gap", [](const ContactPoint& p) { return p.centroid_gap; });
            return out;
          },
          "The contact points as a dict of arrays (zone, fibres, abscissas, contact length, "
          "crossing flag, intermediate tangent, centroid gap).")
      .def(
          "zone_keys",
          [](const Detection& d)
          {
            std::vector<double> k = zone_keys(d);
            carray<double> out({static_cast<py::ssize_t>(d.zones.size()), py::ssize_t(9)});
            std::copy(k.begin(), k.end(), out.mutable_data());
            return out;
          },
          "(zones, 9): each zone as every rank that finds it computes it (fibre_i, fibre_j, "
          "a_i, b_i, a_j, b_j, s_i, s_j, held contact index or -1): the key of the zone "
          "numbers ranks share.")
      .def(
          "renumber_zones",
          [](Detection& d, const carray<int>& global_of_local, int num_zones)
          {
            renumber_zones(d, std::span(global_of_local.data(), global_of_local.size()),
                           num_zones);
          },
          py::arg("global_of_local"), py::arg("num_zones"),
          "Zone z becomes zone global_of_local[z] of num_zones (detection.h).");

  m.def(
      "detect_contacts",
      [](const carray<double>& q, const carray<std::int64_t>& first_node, int order,
         const carray<double>& radius, double delta_factor, double self_exclusion, double spacing,
         double parallel_angle, const py::object& held, const WeavingOrder* weaving,
         const carray<double>& zones, bool keep_kinds, const py::object& present)
      {
        Geometry geo(q, first_node, order, radius);
        if (!present.is_none())
        {
          const auto p = present.cast<carray<bool>>();
          geo.lines.present.assign(p.data(), p.data() + p.size());
        }
        const SectionVectors g{geo.g};
        if (zones.size() % 5 != 0)
          throw std::invalid_argument("detect_contacts: zones must be (n, 5)");
        std::vector<ZoneMark> marks(zones.size() / 5);
        for (std::size_t k = 0; k < marks.size(); ++k)
        {
          const double* w = zones.data() + 5 * k;
          const int kind = static_cast<int>(w[4]);
          if (kind < 0 or kind > 2)
            throw std::invalid_argument("detect_contacts: a zone's kind must be 0, 1 or 2");
          marks[k] = {static_cast<int>(w[0]), static_cast<int>(w[1]), w[2], w[3],
                      static_cast<ZoneKind>(kind)};
        }
        Detection d = detect(geo.lines, g, delta_factor, self_exclusion, spacing, parallel_angle,
                             weaving, marks, keep_kinds);
        if (!held.is_none())
          add_held_contacts(d, geo.lines, g, held_from_arrays(held.cast<py::dict>()));
        return d;
      },
      py::arg("q"), py::arg("first_node"), py::arg("order"), py::arg("radius"),
      py::arg("delta_factor"), py::arg("self_exclusion"), py::arg("spacing"),
      py::arg("parallel_angle"), py::arg("held") = py::none(), py::arg("weaving") = nullptr,
      py::arg("zones") = carray<double>(), py::arg("keep_kinds") = false,
      py::arg("present") = py::none(),
      "One detection pass on the current nodal unknowns q (nodes x 9): a Detection. `held`: "
      "contacts of the last pass not to lose (ContactSet.contacts_to_hold, gathered from "
      "every rank), kept as zones of their own where detection finds none. `weaving`: the "
      "WeavingOrder of the weaving mode (its ordered pairs keep point crossings). `zones`: "
      "(n, 5) fibre_i, fibre_j, s_i, s_j, kind (0 crossing, 1 wrap, 2 line contact) of the "
      "last pass's zones, gathered from every rank (ContactSet.zone_marks): the hysteresis of "
      "the wrap and crossing criteria. `keep_kinds`: the passes within a step keep each "
      "marked zone's kind outright. `present`: one bool per fibre, the fibres whose nodes q "
      "holds (None: all); detection leaves the others out.");

  py::class_<WeavingOrder>(m, "WeavingOrder",
                           "Crossing order of the weaving stage: fibre -> yarn, and "
                           "yarn_above[a, b] = +1 (a above b), -1 (below), 0 (no order).")
      .def(py::init(
               [](const carray<int>& fibre_yarn, const carray<std::int8_t>& above,
                  bool pass_through)
               {
                 if (above.ndim() != 2 or above.shape(0) != above.shape(1))
                   throw std::invalid_argument("WeavingOrder: yarn_above must be square");
                 return WeavingOrder(std::vector<int>(fibre_yarn.data(),
                                                      fibre_yarn.data() + fibre_yarn.size()),
                                     std::vector<std::int8_t>(above.data(),
                                                              above.data() + above.size()),
                                     static_cast<int>(above.shape(0)), pass_through);
               }),
           py::arg("fibre_yarn"), py::arg("yarn_above"), py::arg("pass_through") = false)
      .def_property_readonly("pass_through", &WeavingOrder::pass_through)
      .def_property_readonly("num_fibres", &WeavingOrder::num_fibres)
      .def_property_readonly("num_yarns", &WeavingOrder::num_yarns)
      .def("sign", &WeavingOrder::sign, py::arg("fibre_i"), py::arg("fibre_j"));

  py::class_<PenaltyAdaptation>(m, "PenaltyAdaptation")
      .def(py::init(
               [](double target, double regularization, double band_low, double retune_high,
                  double band_high, double max_change, double k_min, double k_max)
               {
                 PenaltyAdaptation a{target, regularization, band_low, retune_high,
                                     band_high,  max_change,     k_min,    k_max};
                 a.validate();
                 return a;
               }),
           py::arg("target"), py::arg("regularization"), py::arg("band_low"),
           py::arg("retune_high"), py::arg("band_high"), py::arg("max_change"), py::arg("k_min"),
           py::arg("k_max"))
      .def_readonly("target", &PenaltyAdaptation::target)
      .def_readonly("band_low", &PenaltyAdaptation::band_low)
      .def_readonly("band_high", &PenaltyAdaptation::band_high)
      .def_readonly("k_min", &PenaltyAdaptation::k_min)
      .def_readonly("k_max", &PenaltyAdaptation::k_max)
      .def("between_steps", over_zones(&PenaltyAdaptation::between_steps), py::arg("penalty"),
           py::arg("penetration"),
           "Zone penalties for the next step, from each zone's penalty and largest penetration.")
      .def("in_step", over_zones(&PenaltyAdaptation::in_step), py::arg("penalty"),
           py::arg("penetration"),
           "Emergency zone penalties within a step (changed only beyond band_high x target).");

  py::class_<CouplingPattern>(m, "CouplingPattern")
      .def(py::init<>())
      .def("copy", [](const CouplingPattern& self) { return CouplingPattern(self); })
      .def("covers", &CouplingPattern::covers, py::arg("set"), py::arg("margin"))
      .def("add", &CouplingPattern::add, py::arg("set"), py::arg("margin"))
      .def("insert",
           [](const CouplingPattern& self, assembly::SparsityPattern& pattern,
              const carray<std::int32_t>& dofs) { self.insert(pattern, cspan(dofs)); },
           py::arg("pattern"), py::arg("dofs"))
      .def_property_readonly("size", &CouplingPattern::size);

  py::class_<ContactSet>(m, "ContactSet")
      .def(py::init<>())
      .def("copy", [](const ContactSet& self) { return ContactSet(self); })
      .def_property_readonly("size", [](const ContactSet& self) { return self.elements().size(); })
      .def_property_readonly("num_zones", &ContactSet::num_zones)
      .def(
          "next",
          [](const ContactSet& self, const Detection& found, const carray<double>& q,
             const carray<std::int64_t>& first_node, int order, const carray<double>& radius,
             double penalty, double g_r, double mu, double u_rev, double parallel_angle,
             const carray<std::int32_t>& node_owner, int rank, const WeavingOrder* weaving,
             bool reset_normals, const WeavingOrder* woven, bool persist,
             const py::object& group, const py::object& group_mu, int crossing_patch)
          {
            if (crossing_patch != 1 and crossing_patch != 2)
              throw std::invalid_argument("ContactSet.next: crossing_patch must be 1 or 2");
            Geometry geo(q, first_node, order, radius);
            const FrictionCoefficients coefficients = friction_coefficients(
                mu, group, group_mu, radius.size());
            ElementParameters par{penalty, g_r, RegularizedCoulomb{mu, u_rev}, &coefficients,
                                  parallel_angle};
            par.weaving = weaving;
            par.reset_normals = reset_normals;
            par.woven = woven;
            par.persist = persist;
            par.crossing_patch = crossing_patch;
            auto [set, zones] = next_contact_set(self, found, geo.lines, cspan(q), par,
                                                NodeOwners{cspan(node_owner), rank});
            py::dict inherited;
            inherited["penalty"] = array_of(zones.penalty);
            inherited["previous_zone_min"] = array_of(zones.previous_zone_min);
            inherited["previous_zone_max"] = array_of(zones.previous_zone_max);
            inherited["changed_kind"] = array_of(zones.changed_kind);
            return py::make_tuple(std::move(set), inherited);
          },
          py::arg("found"), py::arg("q"), py::arg("first_node"), py::arg("order"),
          py::arg("radius"), py::arg("penalty"), py::arg("g_r"), py::arg("mu"), py::arg("u_rev"),
          py::arg("parallel_angle"), py::arg("node_owner"), py::arg("rank"),
          py::arg("weaving") = nullptr,
          py::arg("reset_normals") = false, py::arg("woven") = nullptr, py::arg("persist") = false,
          py::arg("group") = py::none(), py::arg("group_mu") = py::none(),
          py::arg("crossing_patch") = 2,
          "The set of detection pass `found` with history from this one (evaluated by this "
          "rank: evaluated_here in contact_set.h), and what each new zone inherits. "
          "`weaving`: a WeavingOrder whose ordered pairs take the vertical normal; "
          "`reset_normals`: set normals from the geometry, not from the old elements; "
          "`group` (per fibre, e.g. its yarn, -1 none; None: no groups) and `group_mu` (per "
          "group): two fibres of group g take group_mu[g], other pairs mu "
          "(friction_coefficients.h).")
      .def_static(
          "from_saved",
          [](const py::dict& a, int num_zones, const carray<double>& q,
             const carray<std::int64_t>& first_node, int order, const carray<double>& radius,
             double g_r, double mu, double u_rev, const carray<std::int32_t>& node_owner,
             int rank,
             const py::object& group, const py::object& group_mu, int crossing_patch)
          {
            if (crossing_patch != 1 and crossing_patch != 2)
              throw std::invalid_argument("ContactSet.from_saved: crossing_patch must be 1 or 2");
            const FrictionCoefficients coefficients = friction_coefficients(
                mu, group, group_mu, radius.size());
            Geometry geo(q, first_node, order, radius);
            auto col = [&](const char* name) { return a[name].cast<carray<double>>(); };
            const auto fi = a["fibre_i"].cast<carray<int>>(), fj = a["fibre_j"].cast<carray<int>>();
            const auto zone = a["zone"].cast<carray<int>>();
            const auto crossing = a["crossing"].cast<carray<bool>>();
            const auto wrap = a["wrap"].cast<carray<bool>>();
            // states saved before gap kinds: what a new pass would give
            carray<int> gap_kind(fi.size());
            if (a.contains("gap_kind"))
              gap_kind = a["gap_kind"].cast<carray<int>>();
            else
              for (py::ssize_t e = 0; e < fi.size(); ++e)
                gap_kind.mutable_data()[e] = wrap.data()[e] ? 0 : crossing.data()[e] ? 2 : 1;
            const auto si = col("s_i"), sj = col("s_j"), n = col("normal"), st = col("stick");
            // states saved before the tangents were: from the geometry
            const bool tangents = a.contains("tangent_i") and a.contains("tangent_j");
            const auto ti = tangents ? col("tangent_i") : carray<double>(3 * fi.size());
            const auto tj = tangents ? col("tangent_j") : carray<double>(3 * fi.size());
            const auto len = col("length"), k = col("penalty");
            const auto x1i = col("xi1_i"), x2i = col("xi2_i"), x1j = col("xi1_j"),
                       x2j = col("xi2_j");
            const py::ssize_t size = fi.size();
            for (const auto* arr : {&si, &sj, &len, &k, &x1i, &x2i, &x1j, &x2j})
              if (arr->size() != size)
                throw std::invalid_argument("ContactSet.from_saved: arrays of different lengths");
            if (fj.size() != size or zone.size() != size or crossing.size() != size
                or wrap.size() != size or gap_kind.size() != size or n.size() != 3 * size
                or st.size() != 3 * size or (tangents and (ti.size() != 3 * size
                                                          or tj.size() != 3 * size)))
              throw std::invalid_argument("ContactSet.from_saved: arrays of different lengths");
            std::vector<ContactElementState> elements;
            for (py::ssize_t e = 0; e < size; ++e)
            {
              const SavedElement saved{fi.data()[e],    fj.data()[e],
                                       si.data()[e],    sj.data()[e],
                                       x1i.data()[e],   x2i.data()[e],
                                       x1j.data()[e],   x2j.data()[e],
                                       zone.data()[e],  crossing.data()[e],
                                       wrap.data()[e],  Eigen::Vector3d(n.data() + 3 * e),
                                       len.data()[e],   k.data()[e],
                                       Eigen::Vector3d(st.data() + 3 * e),
                                       static_cast<GapKind>(gap_kind.data()[e]),
                                       tangents ? Eigen::Vector3d(ti.data() + 3 * e)
                                                : Eigen::Vector3d::Zero(),
                                       tangents ? Eigen::Vector3d(tj.data() + 3 * e)
                                                : Eigen::Vector3d::Zero()};
              const RegularizedCoulomb friction{coefficients.mu(saved.fibre_i, saved.fibre_j),
                                                u_rev};
              ContactElementState el
                  = restore_element(geo.lines, saved, g_r, friction, cspan(q), crossing_patch);
              if (evaluated_here(el.fibre_i, el.fibre_j, el.element_node_i(), el.element_node_j(),
                                 NodeOwners{cspan(node_owner), rank}))
                elements.push_back(el);
            }
            return ContactSet(std::move(elements), num_zones);
          },
          py::arg("saved"), py::arg("num_zones"), py::arg("q"), py::arg("first_node"),
          py::arg("order"), py::arg("radius"), py::arg("g_r"), py::arg("mu"), py::arg("u_rev"),
          py::arg("node_owner"), py::arg("rank"), py::arg("group") = py::none(),
          py::arg("group_mu") = py::none(), py::arg("crossing_patch") = 2,
          "The elements of a saved state (a dict of the data() columns, all ranks' elements) "
          "that this rank evaluates (evaluated_here in contact_set.h).")
      .def(
          "handover",
          [](const ContactSet& self, const carray<std::int32_t>& node_owner, int rank,
             const carray<std::int64_t>& first_node, int order, int num_ranks)
          {
            // elements travel between ranks as bytes: plain data (numbers,
            // fixed arrays, Eigen's fixed-size vectors, which hold their
            // coefficients inline), no pointer or owned resource
            static_assert(std::is_standard_layout_v<ContactElementState>
                              and std::is_trivially_destructible_v<ContactElementState>,
                          "contact elements travel between ranks as bytes");
            const auto parts = history_handover(self, NodeOwners{cspan(node_owner), rank},
                                                cspan(first_node), order, num_ranks,
                                                history_match_distance);
            py::list out;
            for (const auto& part : parts)
              out.append(py::bytes(reinterpret_cast<const char*>(part.data()),
                                   part.size() * sizeof(ContactElementState)));
            return out;
          },
          py::arg("node_owner"), py::arg("rank"), py::arg("first_node"), py::arg("order"),
          py::arg("num_ranks"),
          "Per rank, this set's elements whose successor that rank may evaluate, as bytes "
          "for with_history (history_handover.h).")
      .def(
          "with_history",
          [](const ContactSet& self, const py::list& parts)
          {
            std::vector<ContactElementState> received;
            for (const auto& part : parts)
            {
              const std::string bytes = part.cast<std::string>();
              if (bytes.size() % sizeof(ContactElementState))
                throw std::invalid_argument("ContactSet.with_history: not whole elements");
              const std::size_t n = bytes.size() / sizeof(ContactElementState);
              const std::size_t start = received.size();
              received.resize(start + n);
              std::memcpy(static_cast<void*>(received.data() + start), bytes.data(), bytes.size());
            }
            return with_history(self, received);
          },
          py::arg("parts"),
          "This set's elements followed by other ranks' (bytes from handover): a set to "
          "carry history from (next), never to assemble.")
      .def("take_layout", &ContactSet::take_layout, py::arg("previous"),
           "Take over previous's assembly layout if it couples the same nodes.")
      .def("set_zone_penalties", [](ContactSet& self, const carray<double>& k)
           { self.set_zone_penalties(cspan(k)); })
      .def("set_depths", [](ContactSet& self, const carray<double>& d)
           { self.set_depths(cspan(d)); })
      .def("set_depth_scale", &ContactSet::set_depth_scale)
      .def("set_motion_depth", &ContactSet::set_motion_depth, py::arg("depth"),
           "Newton's tangent keeps the points' motion for elements closed by at most depth.")
      .def("set_tangent_floor", &ContactSet::set_tangent_floor, py::arg("fraction"),
           "Every element's tangent floor (regularized_penalty.h) for the next tangents.")
      .def("zone_max_penetration",
           [](const ContactSet& self) { return array_of(self.zone_max_penetration()); })
      .def("zone_penalty", [](const ContactSet& self) { return array_of(self.zone_penalty()); })
      .def("zone_force", [](const ContactSet& self) { return array_of(self.zone_force()); })
      .def("zone_crossed", [](const ContactSet& self) { return array_of(self.zone_crossed()); })
      .def("zone_marks",
           [](const ContactSet& self)
           {
             const auto marks = zone_marks(self);
             carray<double> out({marks.size(), std::size_t(5)});
             for (std::size_t k = 0; k < marks.size(); ++k)
               for (const auto& [c, v] : {std::pair{0, double(marks[k].fibre_i)},
                                          std::pair{1, double(marks[k].fibre_j)},
                                          std::pair{2, marks[k].s_i}, std::pair{3, marks[k].s_j},
                                          std::pair{4, double(static_cast<int>(marks[k].kind))}})
                 out.mutable_at(k, c) = v;
             return out;
           },
           "(n, 4): fibre_i, fibre_j, s_i, s_j of one element of each of this rank's wraps.")
      .def(
          "contacts_to_hold",
          [](const ContactSet& self, const carray<double>& q,
             const carray<std::int64_t>& first_node, int order, const carray<double>& radius,
             double delta_factor)
          {
            Geometry geo(q, first_node, order, radius);
            return held_to_arrays(contacts_to_hold(self, geo.lines, delta_factor));
          },
          py::arg("q"), py::arg("first_node"), py::arg("order"), py::arg("radius"),
          py::arg("delta_factor"),
          "This rank's closed elements (at their last evaluation) that the next detection "
          "might lose, as a dict of arrays (held_contact.h).")
      .def("evaluate", [](ContactSet& self, const carray<double>& q)
           { self.evaluate(cspan(q)); })
      .def("assemble_vector",
           [](ContactSet& self, const carray<double>& q, const carray<std::int32_t>& dofs, Vec b)
           { self.assemble_vector(cspan(q), cspan(dofs), b); })
      .def("assemble_matrix",
           [](ContactSet& self, const carray<double>& q, const carray<std::int32_t>& dofs, Mat A)
           { self.assemble_matrix(cspan(q), cspan(dofs), A); })
      .def("run_kernels", [](ContactSet& self, const carray<double>& q)
           { return self.run_kernels(cspan(q)); },
           "The element kernels of both assemblies alone, nothing inserted (benchmarks).")
      .def("nodal_forces",
           [](const ContactSet& self, const carray<double>& q)
           { return array_of(self.nodal_forces(cspan(q))); })
      .def("nodes", [](const ContactSet& self) { return array_of(self.nodes()); },
           "The global fibre nodes the elements read, sorted (ContactSet::nodes).")
      .def("commit", &ContactSet::commit)
      .def_property_readonly("num_friction_histories", &ContactSet::num_friction_histories)
      .def("timing",
           [](const ContactSet& self)
           {
             py::dict out;
             out["kernel"] = self.timing().kernel;
             out["total"] = self.timing().total;
             out["kernel_calls"] = self.timing().kernel_calls;
             out["off_rank_sent"] = self.timing().off_rank_sent;
             out["off_rank_stashed"] = self.timing().off_rank_stashed;
             return out;
           },
           "Seconds in assemble_vector + assemble_matrix since reset_timing: in the element "
           "kernels and in all; node blocks of other ranks' rows sent to their owners and "
           "stashed by PETSc (counts).")
      .def("reset_timing", &ContactSet::reset_timing)
      .def("data",
           [](const ContactSet& self)
           {
             using Element = ContactElementState;
             py::dict out;
             auto put = [&](const char* name, auto get)
             { out[name] = column(self.elements(), get); };
             put("fibre_i", [](const Element& e) { return e.fibre_i; });
             put("fibre_j", [](const Element& e) { return e.fibre_j; });
             put("zone", [](const Element& e) { return e.zone; });
             put("s_i", [](const Element& e) { return e.s_i; });
             put("s_j", [](const Element& e) { return e.s_j; });
             put("penalty", [](const Element& e) { return e.penalty; });
             put("length", [](const Element& e) { return e.length; });
             put("crossing", [](const Element& e) { return e.crossing; });
             put("gap", [](const Element& e) { return e.result.gap; });
             put("separation", [](const Element& e) { return e.result.separation; });
             put("normal_force", [](const Element& e) { return e.result.normal_force; });
             put("slip", [](const Element& e) { return e.result.slip; });
             put("normal", [](const Element& e) { return e.normal; });
             put("tangential_force", [](const Element& e) { return e.result.tangential_force; });
             put("elastic_slip", [&](const Element& e) { return self.elastic_slip(e); });
             put("stick", [](const Element& e) { return e.stick; });
             put("wrap", [](const Element& e) { return e.wrap; });
             put("gap_kind", [](const Element& e) { return static_cast<int>(e.motion.kind); });
             put("tangent_i", [](const Element& e) { return e.motion.tangent_i; });
             // patch coordinates (particle.h) of the points last measured
             put("measured_xi_i", [](const Element& e) { return e.result.gap_xi[0]; });
             put("measured_xi_j", [](const Element& e) { return e.result.gap_xi[1]; });
             put("tangent_j", [](const Element& e) { return e.motion.tangent_j; });

             put("xi1_i", [](const Element& e) { return e.particle_i.xi1; });
             put("xi2_i", [](const Element& e) { return e.particle_i.xi2; });
             put("xi1_j", [](const Element& e) { return e.particle_j.xi1; });
             put("xi2_j", [](const Element& e) { return e.particle_j.xi2; });
             put("position_i", [](const Element& e) { return e.result.position_i; });
             put("position_j", [](const Element& e) { return e.result.position_j; });
             return out;
           },
           "This rank's elements at their last evaluation, as a dict of arrays (penalty per "
           "unit length, contact length, forces of the element).");
}
