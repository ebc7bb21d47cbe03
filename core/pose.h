// The lab's vocabulary for where things are. Angles are in degrees everywhere in brdfd's
// interfaces (radians only inside math). See docs/geometry.md for the convention.
#pragma once

namespace brdf {

// Holder and detector position: α tilt, β rotation about the lab vertical, γ dial about the
// sample normal, δ the lamp–sample–detector angle. Degrees.
struct Pose {
  double alpha = 0;
  double beta = 0;
  double gamma = 0;
  double delta = 0;
  friend bool operator==(const Pose&, const Pose&) = default;
};

// Incident and outgoing directions in the sample's frame: polar θ from the normal, azimuth φ.
// Degrees; θ in [0, 90] above the surface, φ in (−180, 180].
struct Directions {
  double theta_i = 0;
  double phi_i = 0;
  double theta_o = 0;
  double phi_o = 0;
  friend bool operator==(const Directions&, const Directions&) = default;
};

// The isotropic reduction: (θi, θo, φ) with φ = |φo − φi| folded into [0, 180]. 180 = specular
// side.
struct IsoDirection {
  double theta_i = 0;
  double theta_o = 0;
  double phi = 0;
  friend bool operator==(const IsoDirection&, const IsoDirection&) = default;
};

}  // namespace brdf
