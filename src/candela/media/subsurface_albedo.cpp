#include "candela/media/subsurface_albedo.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>
#include <vector>

namespace candela {

namespace {

// A square matrix of doubles, row-major: the flux carried from stream j (column) into stream i (row).
struct SssMatrix {
  int n = 0;
  std::vector<double> a;
  explicit SssMatrix(int size) : n(size), a(size_t(size) * size, 0.0) {}
  double& operator()(int i, int j) { return a[size_t(i) * n + j]; }
  double operator()(int i, int j) const { return a[size_t(i) * n + j]; }
};

SssMatrix sss_multiply(const SssMatrix& x, const SssMatrix& y) {
  SssMatrix z(x.n);
  for (int i = 0; i < x.n; ++i)
    for (int k = 0; k < x.n; ++k) {
      const double xik = x(i, k);
      if (xik == 0) continue;
      for (int j = 0; j < x.n; ++j) z(i, j) += xik * y(k, j);
    }
  return z;
}

// (I - x)^-1 y, by Gaussian elimination with partial pivoting.
SssMatrix sss_solve_identity_minus(const SssMatrix& x, SssMatrix y) {
  const int n = x.n;
  SssMatrix m(n);
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) m(i, j) = (i == j ? 1.0 : 0.0) - x(i, j);
  for (int col = 0; col < n; ++col) {
    int pivot = col;
    for (int r = col + 1; r < n; ++r)
      if (std::abs(m(r, col)) > std::abs(m(pivot, col))) pivot = r;
    if (pivot != col)
      for (int j = 0; j < n; ++j) {
        std::swap(m(col, j), m(pivot, j));
        std::swap(y(col, j), y(pivot, j));
      }
    const double d = m(col, col);
    if (d == 0) continue;  // singular only for a lossless infinitely thick layer, which never arises
    for (int r = col + 1; r < n; ++r) {
      const double f = m(r, col) / d;
      if (f == 0) continue;
      for (int j = col; j < n; ++j) m(r, j) -= f * m(col, j);
      for (int j = 0; j < n; ++j) y(r, j) -= f * y(col, j);
    }
  }
  for (int col = n - 1; col >= 0; --col) {
    const double d = m(col, col);
    for (int j = 0; j < n; ++j) {
      double v = y(col, j);
      for (int k = col + 1; k < n; ++k) v -= m(col, k) * y(k, j);
      y(col, j) = d != 0 ? v / d : 0.0;
    }
  }
  return y;
}

// Gauss-Legendre nodes and weights on [a, b] (Newton's method on the Legendre polynomial).
void sss_gauss_legendre(int count, double a, double b, std::vector<double>& nodes, std::vector<double>& weights) {
  for (int i = 0; i < count; ++i) {
    double x = std::cos(std::numbers::pi * (i + 0.75) / (count + 0.5));
    double derivative = 1;
    for (int iteration = 0; iteration < 100; ++iteration) {
      double p0 = 1, p1 = x;
      for (int k = 2; k <= count; ++k) {
        const double p2 = ((2.0 * k - 1) * x * p1 - (k - 1.0) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      const double p = count == 1 ? x : p1, p_prev = count == 1 ? 1.0 : p0;
      derivative = count * (x * p - p_prev) / (x * x - 1);
      const double dx = p / derivative;
      x -= dx;
      if (std::abs(dx) < 1e-15) break;
    }
    nodes.push_back(0.5 * (a + b) + 0.5 * (b - a) * x);
    weights.push_back((b - a) / ((1 - x * x) * derivative * derivative));
  }
}

// The unpolarised Fresnel reflectance for light meeting the boundary from inside at cosine mu (relative
// index eta inside / outside): 1 past the critical angle.
double sss_fresnel_from_inside(double mu, double eta) {
  const double relative = 1 / eta;  // outside over inside, as seen from inside
  const double sin2_t = (1 - mu * mu) / (relative * relative);
  if (sin2_t >= 1) return 1;
  const double cos_t = std::sqrt(1 - sin2_t);
  const double r_parallel = (relative * mu - cos_t) / (relative * mu + cos_t);
  const double r_perpendicular = (mu - relative * cos_t) / (mu + relative * cos_t);
  return 0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular);
}

double sss_henyey_greenstein(double cos_theta, double g) {
  const double denominator = 1 + g * g - 2 * g * cos_theta;
  return (1 - g * g) / (4 * std::numbers::pi * denominator * std::sqrt(denominator));
}

// The discrete ordinates: streams at cosines mu_i with quadrature weights w_i over [0, 1], and one
// more stream (the last) along the normal with weight 0, which carries the collimated beam that
// enters and receives no scattered light.
struct SssStreams {
  std::vector<double> mu, weight;
  int count() const { return int(mu.size()); }
  int collimated() const { return count() - 1; }
};

SssStreams sss_streams(double eta) {
  constexpr int kNodesPerRange = 12;
  SssStreams s;
  const double mu_critical = eta > 1 ? std::sqrt(1 - 1 / (eta * eta)) : 0.0;
  if (mu_critical > 0) sss_gauss_legendre(kNodesPerRange, 0, mu_critical, s.mu, s.weight);
  sss_gauss_legendre(mu_critical > 0 ? kNodesPerRange : 2 * kNodesPerRange, mu_critical, 1, s.mu, s.weight);
  s.mu.push_back(1);
  s.weight.push_back(0);
  return s;
}

// The fraction of stream j's scattered flux that goes into stream i: forward (the same vertical
// direction) or backward, Henyey-Greenstein averaged over the azimuth, each column normalised so that
// scattering keeps the flux (the quadrature's own error otherwise adds or removes light).
void sss_redistribution(const SssStreams& s, double g, SssMatrix& forward, SssMatrix& backward) {
  constexpr int kAzimuthSteps = 256;  // the integrand is smooth and periodic: the trapezoid rule converges fast
  const int n = s.count();
  for (int j = 0; j < n; ++j) {
    const double sin_j = std::sqrt(std::max(0.0, 1 - s.mu[j] * s.mu[j]));
    double total = 0;
    for (int i = 0; i < n; ++i) {
      const double sin_i = std::sqrt(std::max(0.0, 1 - s.mu[i] * s.mu[i]));
      double same = 0, opposite = 0;
      for (int k = 0; k < kAzimuthSteps; ++k) {
        const double cos_phi = std::cos(2 * std::numbers::pi * (k + 0.5) / kAzimuthSteps);
        same += sss_henyey_greenstein(s.mu[i] * s.mu[j] + sin_i * sin_j * cos_phi, g);
        opposite += sss_henyey_greenstein(-s.mu[i] * s.mu[j] + sin_i * sin_j * cos_phi, g);
      }
      const double azimuth = 2 * std::numbers::pi / kAzimuthSteps;
      forward(i, j) = s.weight[i] * same * azimuth;
      backward(i, j) = s.weight[i] * opposite * azimuth;
      total += forward(i, j) + backward(i, j);
    }
    for (int i = 0; i < n; ++i) {
      forward(i, j) /= total;
      backward(i, j) /= total;
    }
  }
}

// The streams and their redistribution for one g and eta, which every albedo shares.
struct SssSetup {
  SssStreams streams;
  SssMatrix forward, backward;
  SssSetup(double g, double eta) : streams(sss_streams(eta)), forward(streams.count()), backward(streams.count()) {
    sss_redistribution(streams, g, forward, backward);
  }
};

double sss_effective_albedo(double albedo, double eta, const SssSetup& setup) {
  albedo = std::clamp(albedo, 0.0, 1.0);
  if (albedo == 0) return 0;
  const SssStreams& s = setup.streams;
  const SssMatrix &forward = setup.forward, &backward = setup.backward;
  const int n = s.count();

  // 1. A thin layer, optical thickness 2^-20: each stream is attenuated along its slant path, and
  //    what it loses scatters once (the albedo's share) into the other streams.
  constexpr int kThinLayerExponent = 20, kDoublings = 34;  // to 2^14 optical depths
  const double thin = std::ldexp(1.0, -kThinLayerExponent);
  SssMatrix reflection(n), transmission(n);
  for (int j = 0; j < n; ++j) {
    const double lost = -std::expm1(-thin / s.mu[j]);
    transmission(j, j) = 1 - lost;
    for (int i = 0; i < n; ++i) {
      transmission(i, j) += albedo * forward(i, j) * lost;
      reflection(i, j) = albedo * backward(i, j) * lost;
    }
  }
  // 2. Doubling: two equal layers, the light between them summed over every inter-reflection. The
  //    layer is symmetric, so its reflection and transmission are the same from either side.
  for (int step = 0; step < kDoublings; ++step) {
    const SssMatrix between = sss_solve_identity_minus(sss_multiply(reflection, reflection), transmission);
    reflection = [&] {
      SssMatrix r = sss_multiply(transmission, sss_multiply(reflection, between));
      for (size_t k = 0; k < r.a.size(); ++k) r.a[k] += reflection.a[k];
      return r;
    }();
    transmission = sss_multiply(transmission, between);
  }
  // 3. The boundary on top: the collimated beam enters, the medium reflects u = R d, and the boundary
  //    sends the Fresnel share of u back down: u = R (e + F u), so u = (I - R F)^-1 R e. The rest of u
  //    leaves.
  std::vector<double> fresnel(n);
  for (int i = 0; i < n; ++i) fresnel[i] = sss_fresnel_from_inside(s.mu[i], eta);
  SssMatrix reflection_fresnel(n), entered(n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) reflection_fresnel(i, j) = reflection(i, j) * fresnel[j];
    entered(i, 0) = reflection(i, s.collimated());
  }
  const SssMatrix up = sss_solve_identity_minus(reflection_fresnel, entered);
  double leaving = 0;
  for (int i = 0; i < n; ++i) leaving += (1 - fresnel[i]) * up(i, 0);
  return std::clamp(leaving, 0.0, 1.0);
}

}  // namespace

double subsurface_effective_albedo(double albedo, double g, double eta) {
  return sss_effective_albedo(albedo, eta, SssSetup(g, eta));
}

double subsurface_albedo_from_effective(double effective, double g, double eta) {
  effective = std::clamp(effective, 0.0, 1.0);
  // The effective albedo rises steeply near albedo 1 (as 1 - c sqrt(1 - albedo)): solve for
  // s = sqrt(1 - albedo), in which it is nearly linear, by regula falsi (Illinois variant).
  const SssSetup setup(g, eta);
  auto residual = [&](double s) { return sss_effective_albedo(1 - s * s, eta, setup) - effective; };
  double s0 = 0, s1 = 1;
  double f0 = residual(s0), f1 = residual(s1);  // f0 >= 0 >= f1
  if (f0 <= 0) return 1;
  if (f1 >= 0) return 0;
  int side = 0;
  for (int iteration = 0; iteration < 60 && s1 - s0 > 1e-9; ++iteration) {
    const double s = (s0 * f1 - s1 * f0) / (f1 - f0);
    const double f = residual(s);
    if (std::abs(f) < 1e-9) return 1 - s * s;
    if (f > 0) {
      s0 = s;
      f0 = f;
      if (side == -1) f1 /= 2;
      side = -1;
    } else {
      s1 = s;
      f1 = f;
      if (side == 1) f0 /= 2;
      side = 1;
    }
  }
  const double s = 0.5 * (s0 + s1);
  return 1 - s * s;
}

}  // namespace candela
