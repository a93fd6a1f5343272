#pragma once
// The optional [reference] table of a case file (docs/case-format.md, "[reference]"): the
// analytic solution a run is compared with. robin-plot draws it over the computed contact
// pressure; the solvers do not use it.
//
// Two kinds. "hertz_cylinder" (plane bodies) is plane Hertz line contact of two cylinders with
// parallel axes (a flat body has curvature 0): with P the load per unit thickness, R the effective
// radius (1/R = 1/R1 + 1/R2) and E* the contact modulus (1/E* = 1/E'1 + 1/E'2, E' = E/(1 - nu^2)
// in plane strain and E' = E in plane stress), the contact half-width, peak pressure and
// pressure at distance s from the first contact point are
//   a = sqrt(4 P R / (pi E*)),   p0 = 2 P / (pi a),   p(s) = p0 sqrt(1 - s^2/a^2) for |s| <= a.
// "hertz_sphere" (solid bodies) is Hertz point contact of two spheres (a flat body has curvature
// 0): with P the total load, R the effective radius and E* as above (E' = E/(1 - nu^2)), the
// contact radius, peak pressure and pressure at distance r from the first contact point are
//   a = (3 P R / (4 E*))^(1/3),   p0 = 3 P / (2 pi a^2),   p(r) = p0 sqrt(1 - r^2/a^2), r <= a.

#include <Eigen/Core>
#include <optional>
#include <string>

namespace robin {

class CheckedTable;

enum class ReferenceKind { hertz_cylinder, hertz_sphere };

struct ReferenceSolution {
  ReferenceKind kind = ReferenceKind::hertz_cylinder;
  /// P > 0 (force per unit thickness for a cylinder, force for a sphere); absent: the computed
  /// resultant.
  std::optional<double> load;
  /// The part of the whole problem the model holds (0.5 for a half model, 0.25 for a quarter
  /// one, 1 by default): the computed resultant divided by it is the load P.
  double model_fraction = 1.0;
  double radius = 0.0;           // R > 0, the effective radius
  double contact_modulus = 0.0;  // E* > 0: given, or from the bodies' isotropic materials
  bool contact_modulus_given = false;
  std::optional<Eigen::Vector3d> center;  // the point of first contact (z = 0 in 2D); absent
  std::string location;                   // "case.toml:12", the line of the table
};

/// Reads and validates [reference] of a case file whose [[body]] tables are valid (their
/// materials give the default E*). Throws InputError "FILE:LINE: reference.KEY: problem" for an
/// unknown key, a missing kind or radius, a value out of range, or a missing contact_modulus
/// when a body's material is not isotropic (young, poisson). nullopt when there is no table.
/// `dimension` is the case's: "hertz_cylinder" for plane bodies, "hertz_sphere" for solid ones.
std::optional<ReferenceSolution> read_reference(const CheckedTable& root, int dimension);

/// Hertz's contact half-width a = sqrt(4 P R / (pi E*)) under the load P.
double hertz_half_width(const ReferenceSolution& reference, double load);
/// Hertz's peak pressure p0 = 2 P / (pi a) under the load P.
double hertz_peak_pressure(const ReferenceSolution& reference, double load);
/// Hertz's contact radius a = (3 P R / (4 E*))^(1/3) of point contact under the load P.
double hertz_contact_radius(const ReferenceSolution& reference, double load);
/// Hertz's peak pressure p0 = 3 P / (2 pi a^2) of point contact under the load P.
double hertz_sphere_peak_pressure(const ReferenceSolution& reference, double load);

}  // namespace robin
