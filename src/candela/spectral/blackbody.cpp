#include "candela/spectral/blackbody.h"

#include <cmath>

namespace candela {

double planck(double wavelength_nm, double kelvin, const PlanckRecipe& r) {
  const double l = wavelength_nm * 1e-9;
  const double x = r.h * r.c / (l * r.k * kelvin);
  // scale * 2 * h * c * c in this order: with scale 1 it is exactly 2 * h * c * c.
  return r.scale * 2 * r.h * r.c * r.c / (std::pow(l, 5) * (r.expm1 ? std::expm1(x) : std::exp(x) - 1));
}

}  // namespace candela
