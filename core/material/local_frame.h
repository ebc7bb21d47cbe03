// Directions as unit vectors in the sample frame (t, b, n) of docs/geometry.md ("Frames"): x along
// the tangent t (azimuth φ = 0), y along the bitangent b, z along the normal n. The lobes of a
// material work on these; the angles of core/pose.h become vectors here. Pure.
#pragma once

#include "core/pose.h"

namespace brdf::material {

struct Vec3 {
  double x = 0, y = 0, z = 0;
};

inline double Dot(const Vec3& a, const Vec3& b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

// (sin θ cos φ, sin θ sin φ, cos θ) for θ and φ in degrees.
Vec3 LocalVector(double theta_deg, double phi_deg);

// One evaluation's pair of directions, both pointing away from the surface: wi towards the lamp,
// wo towards the detector. cos_i = wi.z, cos_o = wo.z.
struct DirectionPair {
  Vec3 wi, wo;
  double cos_i() const { return wi.z; }
  double cos_o() const { return wo.z; }
};

DirectionPair ToVectors(const Directions& d);

// The unit half vector of wi and wo, or false when wi + wo is (nearly) zero: both grazing and
// opposite, where no half vector exists.
bool HalfVector(const DirectionPair& d, Vec3& h);

}  // namespace brdf::material
