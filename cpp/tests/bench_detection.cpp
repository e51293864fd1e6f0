// Scaling of one proximity-zone detection pass with the number of fibres
// at constant density (not a ctest test: run ./bench_detection).
//
// Random wavy fibres of 40 quadratic elements fill a cube whose volume grows
// with the fibre count (fibres are folded into it by reflection at its
// faces, so the density is the same near the faces). With O(segments +
// close pairs) detection, 4x the fibres should cost about 4x the time
// (target <= 4.5x); "pair ratio" shows how much the work itself grew, as
// random bundles do not hold exactly 4x the close pairs. 3200 fibres (64x)
// also shows the cost of leaving the CPU caches. Times are the thread's CPU
// time, best of 5: on a shared machine the wall time of the smallest case
// (about 10 ms) swings by 20-30% with what else runs, enough to push the 4x
// ratio past 5 now and then; CPU time does not count waiting for a core.
#include <textile/contact/proximity_zone.h>

#include <Eigen/Dense>

#include <algorithm>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>

using namespace textile::contact;

namespace
{
/// CPU time of the calling thread (ms).
double thread_ms()
{
  timespec t;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return 1e3 * static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_nsec);
}

Centrelines bundle(int num_fibres, unsigned seed)
{
  constexpr int num_elements = 40;
  constexpr double length = 4.0, volume_per_fibre = 0.5;
  const double box = std::cbrt(volume_per_fibre * num_fibres);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Centrelines c;
  c.order = 2;
  c.fibre_offsets.push_back(0);
  for (int f = 0; f < num_fibres; ++f)
  {
    const Eigen::Vector3d start(box * U(gen), box * U(gen), box * U(gen));
    const Eigen::Vector3d d
        = Eigen::Vector3d(U(gen) - 0.5, U(gen) - 0.5, U(gen) - 0.5).normalized();
    const Eigen::Vector3d n
        = d.cross(Eigen::Vector3d(U(gen) - 0.5, U(gen) - 0.5, U(gen) - 0.5)).normalized();
    const double amp = 0.3 * U(gen), waves = 1.0 + 2.0 * U(gen);
    const int nn = 2 * num_elements + 1;
    for (int k = 0; k < nn; ++k)
    {
      const double s = static_cast<double>(k) / (nn - 1);
      Eigen::Vector3d p = start + length * s * d
                          + amp * std::sin(2 * std::numbers::pi * waves * s) * n;
      // fold into the cube by reflection at its faces: continuous fibres,
      // uniform density up to the faces, so no edge effect at small counts
      for (int k3 = 0; k3 < 3; ++k3)
        p[k3] = box - std::abs(std::fmod(std::fmod(p[k3], 2 * box) + 2 * box, 2 * box) - box);
      c.x.insert(c.x.end(), {p[0], p[1], p[2]});
    }
    c.fibre_offsets.push_back(static_cast<std::int64_t>(c.x.size() / 3));
    c.radius.push_back(0.05);
  }
  return c;
}
} // namespace

int main()
{
  const double delta = 2.0, self_exclusion = 0.5;
  const int counts[] = {50, 200, 800, 3200};
  double previous_time = 0, previous_pairs = 0;
  std::printf("%8s %9s %12s %8s %11s %11s %11s\n", "fibres", "segments", "close pairs", "zones",
              "cpu [ms]", "time ratio", "pair ratio");
  for (const int nf : counts)
  {
    const Centrelines c = bundle(nf, 1234u + nf);
    const auto segments = make_segments(c);
    const double pairs = static_cast<double>(
        find_close_pairs(c, segments, delta, self_exclusion).size());
    double best = 1e300;
    std::size_t zones = 0;
    for (int rep = 0; rep < 5; ++rep)
    {
      const double t0 = thread_ms();
      zones = find_proximity_zones(c, delta, self_exclusion).size();
      best = std::min(best, thread_ms() - t0);
    }
    auto ratio = [](double now, double before)
    { return before > 0 ? std::to_string(now / before).substr(0, 5) : std::string("-"); };
    std::printf("%8d %9zu %12.0f %8zu %11.3f %11s %11s\n", nf, segments.size(), pairs, zones, best,
                ratio(best, previous_time).c_str(), ratio(pairs, previous_pairs).c_str());
    previous_time = best;
    previous_pairs = pairs;
  }
  return 0;
}
