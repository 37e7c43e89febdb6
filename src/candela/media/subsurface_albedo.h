#pragma once
// The effective albedo of a subsurface medium: what fraction of the light that a smooth dielectric
// boundary lets into a semi-infinite homogeneous medium comes out again. It is pbrt-v4's "rhoEff"
// (the integral of its BSSRDF's radial profile: light refracted in at normal incidence, carried by
// photon beam diffusion, leaving through the boundary) for the exact radiative transfer that
// candela's random walk (volpath) estimates, and the map that turns pbrt-v4's "reflectance" of a
// "subsurface" material into the medium's single-scattering albedo.
//
// Computed by adding-doubling (van de Hulst 1980; Prahl 1995, "The Adding-Doubling Method") of the
// plane-parallel, azimuthally averaged transport equation: discrete ordinates in the cosine mu
// (Gauss-Legendre nodes, split at the boundary's critical angle where the Fresnel reflectance has its
// kink), Henyey-Greenstein scattering averaged over azimuth and renormalised per direction, a thin
// layer of single scattering doubled to an optical thickness of 2^14 (semi-infinite to well below
// 1e-4 for any albedo below 1), under the boundary's Fresnel reflection (unpolarised, relative index
// eta; total internal reflection below the critical angle). The light enters as a collimated beam
// along the normal.

namespace candela {

// The effective albedo of a medium of single-scattering albedo `albedo` in [0, 1] and Henyey-Greenstein
// mean cosine g in (-1, 1) under a smooth boundary of relative index eta (inside / outside, > 0):
// in [0, 1], increasing with the albedo.
double subsurface_effective_albedo(double albedo, double g, double eta);

// Its inverse: the single-scattering albedo whose effective albedo is `effective` (clamped to [0, 1]).
double subsurface_albedo_from_effective(double effective, double g, double eta);

}  // namespace candela
