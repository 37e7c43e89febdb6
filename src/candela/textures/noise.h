#pragma once
// Perlin noise and its sums over octaves, for the solid and dot textures (description/textures.h).
// The lattice's permutation is Ken Perlin's reference one and the gradients and sums are those of
// pbrt-v4's Noise, FBm and Turbulence, so that candela's procedural textures show the pattern of
// pbrt-v4's renders of the same scene.
#include "candela/math/vec.h"

namespace candela {

// Gradient noise at p: zero at every integer point, smooth (C2, the quintic fade), within about
// [-1, 1] and with mean zero over space.
float perlin_noise(Point3 p);

// The sum over `octaves` octaves of omega^i noise(1.99^i p): fractional Brownian motion.
float fbm(Point3 p, float omega, int octaves);

// The same sum of |noise(1.99^i p)| (turbulence), plus 0.2 omega^octaves for the octaves left out
// (0.2 is about the mean of |noise|), as pbrt-v4 adds for a fully resolved point.
float turbulence(Point3 p, float omega, int octaves);

}  // namespace candela
