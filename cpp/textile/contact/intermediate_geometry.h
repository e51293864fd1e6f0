// Intermediate geometry of a proximity zone and the contact elements on it
// (docs/method.md §3.4-3.5).
//
// For a zone [a_i, b_i] x [a_j, b_j] between fibres i and j,
//     x_int(s) = 1/2 [x0_i((1-s) a_i + s b_i) + x0_j((1-s) a_j + s b_j)],  s in [0, 1],
// treats both fibres symmetrically; its tangent is the mean of the two unit
// tangents. Contact elements sit at c_l = x_int(l / (n_c + 1)), l = 1..n_c.
// At c_l the plane orthogonal to the intermediate tangent cuts each centre
// line (abscissas s_i, s_j); the centroid-to-centroid direction, projected
// on each (deformed) section, meets the section border at the particles.
#pragma once

#include "centreline.h"
#include "tolerances.h"
#include "closest_points.h"
#include "proximity_zone.h"

#include <Eigen/Dense>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace textile::contact
{

/// Nodes of the element containing abscissa s of fibre f (the last element
/// at s = num_elements), and the local coordinate there: fills
/// nodes[0..order] with global node numbers and returns xi in [-1, 1].
double element_of(const Centrelines& c, int f, double s, std::array<std::int64_t, 3>& nodes);

/// Section vectors of all nodes, numbered as the Centrelines' nodes:
/// node n's g1 at g[stride n + offset], its g2 right after it (6 per node
/// [g1, g2] by default; the nodal unknowns [x0, g1, g2] are stride 9,
/// offset 3).
struct SectionVectors
{
  std::span<const double> g;
  std::size_t stride = 6;
  std::size_t offset = 0;
  /// Interpolated g1, g2 at abscissa s of fibre f.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> at(const Centrelines& c, int f, double s) const;
};

/// One contact element's geometry: where its two particles are.
struct ContactPoint
{
  int fibre_i = 0, fibre_j = 0;
  double s_i = 0, s_j = 0;             ///< abscissas of the sections
  double xi1_i = 0, xi2_i = 0;         ///< particle of fibre i (section coordinates, length)
  double xi1_j = 0, xi2_j = 0;         ///< particle of fibre j
  double parameter = 0;                ///< position in [0, 1] on the intermediate geometry
  bool crossing = false;               ///< a crossing's single element (else one of a line contact's)
  bool wrap = false;                   ///< an element of a wrap (wrap_contact.h)
  double length = 0;                   ///< contact length it stands for (see crossing_length)
  Eigen::Vector3d tangent_i = Eigen::Vector3d::Zero(); ///< unit centre-line tangent at s_i
  Eigen::Vector3d tangent_j = Eigen::Vector3d::Zero(); ///< and at s_j
  Eigen::Vector3d tangent = Eigen::Vector3d::Zero();   ///< unit intermediate tangent
  Eigen::Vector3d centroid_gap = Eigen::Vector3d::Zero(); ///< x0_i(s_i) - x0_j(s_j)
  /// The normal of an earlier pass held for this point (held_contact.h):
  /// its fibres have crossed along it. Zero: the normal is set anew.
  Eigen::Vector3d held_normal = Eigen::Vector3d::Zero();
};

/// Unit tangent of fibre f's centre line smoothed to C1 at its nodes
/// (Centrelines::smooth_tangent) at abscissa s; at a node, the mean of the
/// two elements' tangents (a kink's, where a force bends the fibre).
Eigen::Vector3d unit_tangent(const Centrelines& c, int f, double s);

/// Unit tangent of fibre f at abscissa s, continuous in s across nodes:
/// within kink_blend (element coordinates) of an interior node, the
/// element's tangent is turned by part of the kink, (1 - |s - node| /
/// kink_blend) / 2 of the jump of unit tangents at the node, so that both
/// sides meet at the bisector (unit_tangent at the node); elsewhere the
/// element's tangent. A normal built from it turns smoothly as a point
/// moves across a kinked node instead of jumping by the kink angle.
Eigen::Vector3d blended_tangent(const Centrelines& c, int f, double s);

/// Mean of two unit tangents, the second flipped if the fibres run in
/// opposite directions (an intermediate geometry has no orientation).
Eigen::Vector3d mean_tangent(const Eigen::Vector3d& ti, const Eigen::Vector3d& tj);

/// Equivalent contact length of a crossing (point contact) between fibres
/// of radii r_i and r_j: r_i + r_j, the distance of their centre lines at
/// touch. A crossing's single element stands for this length of line
/// contact, so that one penalty per unit length (contact_set.h) serves both
/// kinds of zone; a zone that changes kind has its penalty converted so its
/// force is continuous (FibreContact).
double crossing_length(double r_i, double r_j);

/// Length of the intermediate geometry (polyline through `samples` points).
double intermediate_length(const Centrelines& c, const ProximityZone& z, int samples = 9);

/// Whether a zone is a crossing (a point contact): the tangents at its
/// closest points make an angle above `parallel_angle` (radians) AND the
/// centre lines move apart at both ends of the zone (distance above the
/// mean of the smallest distance and the search distance delta_factor
/// (r_i + r_j)). Twisted or wound fibres cross at an angle but stay close
/// up to a fibre end: they touch along a line.
///
/// `bias` (hysteresis, detection.h): the angle threshold is (1 - bias)
/// parallel_angle and the ends' distance threshold lies at (1/2 - bias) of
/// the way from the smallest distance to the search distance; +crossing_bias
/// for a zone that was a crossing, -crossing_bias for one that was a line
/// contact, 0 for a new zone.
bool is_crossing(const Centrelines& c, const ProximityZone& z, double parallel_angle,
                 double delta_factor, double bias = 0.0);

/// Element boundaries of a fibre strictly inside (a, b) (abscissas),
/// appended to `cuts` as fractions of [a, b].
void add_element_cuts(double a, double b, std::vector<double>& cuts);

/// A composite 2-point Gauss rule on [0, 1] for a curve of `length`: cut at
/// `cuts` (fractions, any order; pieces shorter than spacing / 1000
/// merged into a neighbour), each piece cut again into parts of about
/// 2 x spacing (up to 2.2 x spacing not cut). Returns the points and their
/// weights (fractions of [0, 1], summing to 1).
/// @throws GeometryError for a length above 1e6 x spacing (a diverged
///         iterate: the step is cut).
std::pair<std::vector<double>, std::vector<double>>
composite_gauss_rule(std::vector<double> cuts, double length, double spacing);

/// Contact elements of a zone.
///
/// Line contacts (see is_crossing): elements at
/// the points of a composite 2-point Gauss rule on the intermediate
/// geometry, cut at both fibres' element boundaries (cuts closer than
/// spacing / 1000 merged) and about every 2 x spacing (pieces up to 2.2 x
/// spacing are not cut), each standing for its share of the intermediate geometry's
/// length (its Gauss weight times the half-length of its piece; the lengths
/// of a zone sum to the zone's length, whatever the spacing): a contact
/// element's force is length x R_N(gap), R_N per unit length.
/// Crossing fibres touch at a point: one element at the closest points of
/// the two centre lines, where the centroid gap is along t_i x t_j (several
/// elements off the crossing would measure the gap between points on the
/// sides of the sections and let the fibres through); it stands for
/// crossing_length(r_i, r_j).
///
/// End caps are excluded: no element is made where the centroid gap runs
/// within about 8 degrees of a fibre's axis (a fibre end pushed head-on into
/// another fibre); the side of a fibre near its end is handled as usual.
///
/// @param spacing  target distance between contact elements (length > 0),
///                 typically the fibre element length or less.
/// A crossing zone one of whose fibres wraps around the other by more than
/// `wrap_angle` (radians) over at least 2 x spacing (wrap_contact.h: long
/// enough for 2 pieces of elements) gets the wrap's elements instead (a
/// negative wrap_angle: never). `kind_bias`: is_crossing's hysteresis.
///
/// @param fallback direction used to place the particles when the two
///                 centroids coincide (e.g. the element's previous normal,
///                 pointing from j to i); zero: t_i x t_j or any normal.
std::vector<ContactPoint> contact_points(const Centrelines& c, const SectionVectors& g,
                                         const ProximityZone& z, double spacing,
                                         double parallel_angle, double delta_factor,
                                         const Eigen::Vector3d& fallback = Eigen::Vector3d::Zero(),
                                         double wrap_angle = -1.0,
                                         double kind_bias = 0.0);

/// Place p's particles on the borders of its two sections where they face
/// each other along `towards_j` (from fibre i towards fibre j; fibre j's
/// particle faces -towards_j): sets xi1_i, xi2_i, xi1_j, xi2_j.
/// @throws GeometryError if the direction is along a fibre's axis.
void place_particles(const Centrelines& c, const SectionVectors& g, ContactPoint& p,
                     const Eigen::Vector3d& towards_j);

/// Abscissa on fibre f where the plane through `point` orthogonal to
/// `normal` cuts the centre line, searched from `guess` (Newton with
/// bisection safeguard), clamped to [0, num_elements(f)].
double section_cut(const Centrelines& c, int f, const Eigen::Vector3d& point,
                   const Eigen::Vector3d& normal, double guess);

/// Section coordinates (xi1, xi2) of the border point of a section (g1, g2,
/// radius R) in the direction of d projected on the section plane.
Eigen::Vector2d border_particle(const Eigen::Vector3d& g1, const Eigen::Vector3d& g2, double R,
                                const Eigen::Vector3d& d);

} // namespace textile::contact
