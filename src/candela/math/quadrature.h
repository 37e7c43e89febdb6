#pragma once
// Gauss-Legendre quadrature: n nodes and weights on [-1, 1] that integrate polynomials of degree
// 2n - 1 exactly. Used where an integral over a smooth integrand is precomputed once (the rough
// coat's tables in materials/rough_coat.h).
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace candela {

struct QuadratureRule {
  std::vector<double> nodes, weights;
};

// The nodes are the roots of the Legendre polynomial P_n, found by Newton's method from the
// Chebyshev-like first guess cos(pi (i + 3/4) / (n + 1/2)); the weights are 2 / ((1 - x^2) P_n'(x)^2).
inline QuadratureRule gauss_legendre(int n) {
  QuadratureRule rule;
  rule.nodes.resize(size_t(n));
  rule.weights.resize(size_t(n));
  for (int i = 0; i < (n + 1) / 2; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (n + 0.5));
    double derivative = 1;
    for (int iteration = 0; iteration < 100; ++iteration) {
      // P_n(x) and P_{n-1}(x) by the three-term recurrence.
      double p0 = 1, p1 = x;
      for (int k = 2; k <= n; ++k) {
        double p2 = ((2 * k - 1) * x * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      derivative = n * (x * p1 - p0) / (x * x - 1);
      double step = p1 / derivative;
      x -= step;
      if (std::abs(step) < 1e-15) break;
    }
    double w = 2 / ((1 - x * x) * derivative * derivative);
    rule.nodes[size_t(i)] = -x;
    rule.nodes[size_t(n - 1 - i)] = x;
    rule.weights[size_t(i)] = rule.weights[size_t(n - 1 - i)] = w;
  }
  return rule;
}

}  // namespace candela
