// Current centre lines of the fibres, as seen by contact detection.
//
// Only the centroids x0 of the nodes are needed to find proximity zones
// (docs/method.md §3.2), so this view holds 3 numbers per node instead of
// the 9 unknowns of the beam element. Nodes are numbered fibre after fibre,
// as in textile/fibre_mesh.py; element e of fibre f has the nodes
// order*e + a, a = 0..order, counted from the fibre's first node.
//
// Abscissa convention (used by every contact-detection function): a point
// of fibre f is named by a continuous element coordinate s in
// [0, num_elements(f)]. Element e = floor(s) (the last element for
// s = num_elements), local coordinate xi = 2 (s - e) - 1 in [-1, 1], and the
// position is interpolated with the element's Lagrange shape functions,
// exactly as in the beam element (beam/beam_element.cpp). s is
// dimensionless; lengths are in the unit of the coordinates.
#pragma once

#include <Eigen/Core>
#include "tolerances.h"

#include <cstdint>
#include <vector>

namespace textile::contact
{

/// Centroid lines of all fibres in the current configuration.
struct Centrelines
{
  std::vector<double> x;                    ///< 3 coordinates per node, fibre after fibre
  std::vector<std::int64_t> fibre_offsets;  ///< first node of each fibre, size nfib+1, starts at 0
  int order = 1;                            ///< element order: 1 (2 nodes) or 2 (3 nodes)
  std::vector<double> radius;               ///< fibre radius (length, > 0), one per fibre
  /// Which fibres this view holds (one flag per fibre; empty: all). On
  /// several ranks a rank detects among the fibres near its own elements
  /// (textile/effects/fibre_contact.py, ghost fibres): the others' nodes
  /// are not here (NaN), and detection leaves those fibres out.
  std::vector<char> present;

  /// Whether fibre f's nodes are in this view (see `present`).
  bool has(int f) const { return present.empty() or present[f] != 0; }

  /// Throws std::invalid_argument naming the first inconsistency: order not
  /// 1 or 2, offsets not starting at 0 / decreasing / not ending at the node
  /// count, a fibre without a whole number (>= 1) of elements, a radius that
  /// is not finite and positive, `present` not one flag per fibre;
  /// GeometryError for a coordinate of a present fibre that is NaN or
  /// infinite (a diverged state).
  void validate() const;

  /// Number of fibres.
  int num_fibres() const;

  /// Number of elements of fibre f, (nodes - 1) / order.
  int num_elements(int f) const;

  /// Centroid position at abscissa s in [0, num_elements(f)] of fibre f
  /// (length). Throws std::invalid_argument for s outside that range.
  Eigen::Vector3d position(int f, double s) const;

  /// Derivative dx0/ds at abscissa s of fibre f (length per unit s, not
  /// normalised; dx0/dxi = 1/2 dx0/ds). At a node shared by two elements the
  /// element on the right is used, except at the fibre's end.
  Eigen::Vector3d tangent(int f, double s) const;

  /// dx0/ds from the element on the left of s: the same as tangent() except
  /// at an interior node, where a centre line (C0 between elements) may
  /// have a kink.
  Eigen::Vector3d tangent_left(int f, double s) const;

  /// Centroid position at abscissa s on fibre f's centre line *smoothed to
  /// C1* across its interior nodes, the line a contact patch sees
  /// (particle.h): within patch_smoothing (element lengths) of an interior
  /// node, the two elements' polynomials, each continued past the node, are
  /// blended, x = (1 - phi) x_left + phi x_right, phi = 3 tau^2 - 2 tau^3,
  /// tau from 0 to 1 across the window; elsewhere (and at the fibre's ends)
  /// the element's own polynomial. It passes through every node. Contact
  /// detection searches crossings on this line so that it finds the point
  /// Newton's facing point settles at (gap_function.h), not the C0 line's
  /// kink at a node.
  Eigen::Vector3d smooth_position(int f, double s) const;

  /// d/ds of smooth_position (continuous in s).
  Eigen::Vector3d smooth_tangent(int f, double s) const;
};

/// A straight piece of a centre line used by the broad and narrow phases.
///
/// Each element is cut into `order` chords between consecutive nodes (a
/// linear element is its own chord; a quadratic element gives two chords,
/// xi in [-1, 0] and [0, 1]). The point at chord parameter t in [0, 1] is
/// p0 + t (p1 - p0) and stands for the centre-line point at abscissa
/// s0 + t (s1 - s0). For a curved quadratic element the two differ by at
/// most `sag` (= |x_a - 2 x_b + x_c| / 8, the exact bound on a quadratic's
/// deviation from its linear interpolant over half the element), which
/// the detection adds to its distance criterion so that no close pair of
/// the true curves is missed.
struct Segment
{
  int fibre = 0;        ///< fibre number
  int index = 0;        ///< segment number within the fibre, 0 .. order*num_elements-1
  double s0 = 0, s1 = 0;      ///< abscissas (element coordinate) of the end points
  double arc0 = 0, arc1 = 0;  ///< chord-polyline length from the fibre start to the end points
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero(); ///< first end point
  Eigen::Vector3d p1 = Eigen::Vector3d::Zero(); ///< second end point
  double sag = 0;       ///< bound on the chord-to-curve distance (length, >= 0)
};

/// All segments, fibre after fibre, in increasing abscissa: the global
/// segment number of (fibre f, index k) is the number of segments of the
/// fibres before f plus k. Validates `c` first.
/// (Fibres not present, see Centrelines::present, have none.)
std::vector<Segment> make_segments(const Centrelines& c);

} // namespace textile::contact
