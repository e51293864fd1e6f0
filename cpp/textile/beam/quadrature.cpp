#include "quadrature.h"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace textile::beam
{

GaussLegendre gauss_legendre(int n)
{
  if (n < 1 or n > 64)
    throw std::invalid_argument("gauss_legendre: number of points must be in [1, 64], got "
                                + std::to_string(n));
  GaussLegendre rule;
  rule.points.resize(n);
  rule.weights.resize(n);
  // Newton iteration on P_n from Chebyshev initial guesses; symmetric pairs.
  for (int i = 0; i < (n + 1) / 2; ++i)
  {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double dp = 0;
    for (int it = 0; it < 100; ++it)
    {
      double p0 = 1.0, p1 = x;
      for (int k = 2; k <= n; ++k)
      {
        const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const double pn = (n == 1) ? x : p1;
      const double pnm1 = (n == 1) ? 1.0 : p0;
      dp = n * (x * pn - pnm1) / (x * x - 1.0);
      const double dx = pn / dp;
      x -= dx;
      if (std::abs(dx) < 1e-16)
        break;
    }
    // recompute derivative at the converged root for the weight
    double p0 = 1.0, p1 = x;
    for (int k = 2; k <= n; ++k)
    {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    const double pn = (n == 1) ? x : p1;
    const double pnm1 = (n == 1) ? 1.0 : p0;
    dp = n * (x * pn - pnm1) / (x * x - 1.0);
    const double w = 2.0 / ((1.0 - x * x) * dp * dp);
    rule.points[i] = -x;
    rule.points[n - 1 - i] = x;
    rule.weights[i] = w;
    rule.weights[n - 1 - i] = w;
  }
  if (n % 2 == 1)
    rule.points[n / 2] = 0.0;
  return rule;
}

SectionQuadrature disk_quadrature(double radius, int order)
{
  if (!(radius > 0) or !std::isfinite(radius))
    throw std::invalid_argument("disk_quadrature: radius must be positive and finite");
  if (order < 2 or order > 40)
    throw std::invalid_argument("disk_quadrature: order must be in [2, 40], got "
                                + std::to_string(order));
  SectionQuadrature q;
  q.radius = radius;
  q.order = order;
  const double area = std::numbers::pi * radius * radius;
  if (order == 4 or order == 5)
  {
    // Radon: the hexagon's equally spaced angles integrate the angular
    // parts of degree < 6 exactly; centre and ring weights match the
    // moments 1, r^2, r^4
    q.xi1 = {0.0};
    q.xi2 = {0.0};
    q.weights = {0.25 * area};
    const double r = radius * std::sqrt(2.0 / 3.0);
    for (int j = 0; j < 6; ++j)
    {
      const double t = std::numbers::pi * j / 3.0;
      q.xi1.push_back(r * std::cos(t));
      q.xi2.push_back(r * std::sin(t));
      q.weights.push_back(area / 8.0);
    }
    return q;
  }
  // integrand of degree `order` times the Jacobian r: degree order+1 in r
  const int nr = order / 2 + 1;
  const int nt = order + 1;
  const GaussLegendre gl = gauss_legendre(nr);
  const double dtheta = 2.0 * std::numbers::pi / nt;
  for (int i = 0; i < nr; ++i)
  {
    const double r = 0.5 * radius * (gl.points[i] + 1.0);
    const double wr = 0.5 * radius * gl.weights[i] * r;
    for (int j = 0; j < nt; ++j)
    {
      // offset angle so that no point sits on a section axis for every order
      const double t = dtheta * (j + 0.5 * (i % 2));
      q.xi1.push_back(r * std::cos(t));
      q.xi2.push_back(r * std::sin(t));
      q.weights.push_back(wr * dtheta);
    }
  }
  return q;
}

} // namespace textile::beam
