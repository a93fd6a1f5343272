#pragma once
// Linear elastic material in 2D Voigt notation.
// stress = C strain with stress = (s_xx, s_yy, s_xy) and engineering strain
// (e_xx, e_yy, 2 e_xy); C is the paper's A_ijkl reduced to the plane.

#include <Eigen/Core>
#include <string>

namespace robin {

enum class PlaneModel { plane_strain, plane_stress };

struct Material {
  Eigen::Matrix3d stiffness = Eigen::Matrix3d::Identity();  // C, symmetric positive definite
  PlaneModel model = PlaneModel::plane_strain;
  /// Out-of-plane stress s_zz = c'(s_xx, s_yy) stress factors: s_zz = nu (s_xx + s_yy) for an
  /// isotropic plane-strain material, zero for plane stress and general Voigt input.
  double out_of_plane_poisson = 0.0;
};

/// Isotropic material. Throws InputError (message prefixed by `context`, e.g.
/// "case.toml: body 'upper': material") when young <= 0 or poisson outside (-1, 0.5).
Material make_isotropic_material(double young, double poisson, PlaneModel model,
                                 const std::string& context);

/// General symmetric Voigt stiffness. Throws InputError when C is not symmetric
/// (relative 1e-12) or not positive definite.
Material make_voigt_material(const Eigen::Matrix3d& stiffness, PlaneModel model,
                             const std::string& context);

/// Von Mises stress of an in-plane stress (s_xx, s_yy, s_xy) with out-of-plane s_zz.
double von_mises(const Eigen::Vector3d& stress, double stress_zz);

/// Out-of-plane stress s_zz = out_of_plane_poisson (s_xx + s_yy) of `material`.
double out_of_plane_stress(const Material& material, const Eigen::Vector3d& stress);

/// Von Mises stress of an in-plane stress of `material`, with s_zz from out_of_plane_stress.
double von_mises(const Material& material, const Eigen::Vector3d& stress);

}  // namespace robin
