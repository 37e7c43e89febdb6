#include "candela/spectral/rgb_to_spectrum_table.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "candela/spectral/cie.h"

namespace candela {

namespace {

constexpr int kFitResolution = kRgbToSpectrumResolution;

// The fit works on the trapezoid rule over the 5 nm samples of the tables (exact for their linear
// interpolation), with the D65-weighted matching functions divided by the luminance integral (so
// that the constant spectrum 1 has Y = 1).
struct Quadrature {
  static constexpr int kPoints = 95;
  double t[kPoints];
  cie::Xyz weight[kPoints];
  cie::Xyz white;  // XYZ of the constant spectrum 1 under D65: the CIELAB white point
  Quadrature() {
    double norm = 1.0 / cie::y_integral();
    for (int i = 0; i < kPoints; ++i) {
      double lambda = cie::kLambdaMin + 5 * i;
      t[i] = double(i) / (kPoints - 1);
      cie::Xyz m = cie::matching(lambda);
      double w = cie::d65(lambda) * norm * (i == 0 || i == kPoints - 1 ? 2.5 : 5.0);
      weight[i] = {m.x * w, m.y * w, m.z * w};
      white.x += weight[i].x;
      white.y += weight[i].y;
      white.z += weight[i].z;
    }
  }
};

const Quadrature& quadrature() {
  static const Quadrature q;
  return q;
}

double lab_f(double t) { return t > 216.0 / 24389.0 ? std::cbrt(t) : (24389.0 / 27.0 * t + 16) / 116; }

std::array<double, 3> to_lab(const cie::Xyz& c, const cie::Xyz& white) {
  double fx = lab_f(c.x / white.x), fy = lab_f(c.y / white.y), fz = lab_f(c.z / white.z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

// CIELAB of the sigmoid spectrum with coefficients c (normalised t) under D65.
std::array<double, 3> spectrum_lab(const std::array<double, 3>& c) {
  const Quadrature& q = quadrature();
  cie::Xyz xyz;
  for (int i = 0; i < Quadrature::kPoints; ++i) {
    double x = (c[0] * q.t[i] + c[1]) * q.t[i] + c[2];
    double s = 0.5 + x / (2 * std::sqrt(1 + x * x));
    xyz.x += s * q.weight[i].x;
    xyz.y += s * q.weight[i].y;
    xyz.z += s * q.weight[i].z;
  }
  return to_lab(xyz, q.white);
}

// Gauss-Newton on the CIELAB difference (forward-difference Jacobian), starting from c.
void fit(const std::array<double, 3>& rgb, std::array<double, 3>& c) {
  const std::array<double, 3> target = to_lab(cie::linear_srgb_to_xyz(rgb[0], rgb[1], rgb[2]), quadrature().white);
  for (int iteration = 0; iteration < 30; ++iteration) {
    std::array<double, 3> lab = spectrum_lab(c), r;
    for (int k = 0; k < 3; ++k) r[k] = lab[k] - target[k];
    double err = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    if (err < 1e-8) return;  // CIELAB units: far below what anyone sees
    double J[3][3];
    for (int j = 0; j < 3; ++j) {
      std::array<double, 3> cp = c;
      const double h = 1e-5;
      cp[j] += h;
      std::array<double, 3> lp = spectrum_lab(cp);
      for (int k = 0; k < 3; ++k) J[k][j] = (lp[k] - lab[k]) / h;
    }
    // Solve J d = -r by Cramer's rule (3 x 3).
    auto det3 = [](double a[3][3]) {
      return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
             a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    double det = det3(J);
    if (!(std::abs(det) > 1e-15)) return;
    std::array<double, 3> d;
    for (int j = 0; j < 3; ++j) {
      double M[3][3];
      for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) M[a][b] = b == j ? -r[a] : J[a][b];
      d[j] = det3(M) / det;
    }
    // Halve the step until the error falls (the sigmoid saturates: full steps can overshoot).
    double step = 1;
    for (int tries = 0; tries < 20; ++tries, step *= 0.5) {
      std::array<double, 3> cn = {c[0] + step * d[0], c[1] + step * d[1], c[2] + step * d[2]};
      std::array<double, 3> ln = spectrum_lab(cn);
      double en = 0;
      for (int k = 0; k < 3; ++k) en += (ln[k] - target[k]) * (ln[k] - target[k]);
      if (en < err) {
        c = cn;
        break;
      }
    }
    if (step < 1e-5) return;
    // Keep the polynomial bounded: beyond this the spectrum is a step and the fit gains nothing.
    double m = std::max({std::abs(c[0]), std::abs(c[1]), std::abs(c[2])});
    if (m > 200) {
      for (double& v : c) v *= 200 / m;
    }
  }
}


}  // namespace

void fit_rgb_to_spectrum_row(int l, int yi, float* table) {
  const double y = double(yi) / (kFitResolution - 1);
  for (int xi = 0; xi < kFitResolution; ++xi) {
    const double x = double(xi) / (kFitResolution - 1);
    // Start at a middling brightness from the zero polynomial, then walk up and down in z, each fit
    // starting from its neighbour's coefficients.
    const int start = kFitResolution / 5;
    auto solve_at = [&](int zi, std::array<double, 3>& c) {
      const double z = rgb_to_spectrum_z_node(zi);
      std::array<double, 3> rgb;
      rgb[size_t(l)] = z;
      rgb[size_t(l + 1) % 3] = x * z;
      rgb[size_t(l + 2) % 3] = y * z;
      fit(rgb, c);
      float* out = table + rgb_to_spectrum_index(l, zi, yi, xi);
      for (int k = 0; k < 3; ++k) out[k] = float(c[size_t(k)]);
    };
    std::array<double, 3> c = {0, 0, 0};
    for (int zi = start; zi < kFitResolution; ++zi) solve_at(zi, c);
    c = {0, 0, 0};
    for (int zi = start; zi >= 0; --zi) solve_at(zi, c);
  }
}

}  // namespace candela
