#pragma once
// Linear elastic material in Voigt notation, stress = C strain.
//  - Plane bodies: stress (s_xx, s_yy, s_xy), engineering strain (e_xx, e_yy, 2 e_xy); C (3 x 3)
//    is the paper's A_ijkl reduced to the plane (plane strain or plane stress).
//  - Solid bodies: stress (s_xx, s_yy, s_zz, s_yz, s_xz, s_xy), engineering strain
//    (e_xx, e_yy, e_zz, 2 e_yz, 2 e_xz, 2 e_xy) (the standard Voigt order 11, 22, 33, 23, 13,
//    12); C (6 x 6) is A_ijkl itself.

#include <Eigen/Core>
#include <string>

namespace robin {

enum class PlaneModel { plane_strain, plane_stress };

/// The stress tensor in ParaView's symmetric-tensor order XX, YY, ZZ, XY, YZ, XZ.
using StressTensor = Eigen::Matrix<double, 6, 1>;

struct Material {
  /// C, symmetric positive definite: 3 x 3 for a plane body, 6 x 6 for a solid body.
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Identity(3, 3);
  /// The plane reduction (plane bodies only).
  PlaneModel model = PlaneModel::plane_strain;
  /// Out-of-plane stress s_zz = c'(s_xx, s_yy) stress factors: s_zz = nu (s_xx + s_yy) for an
  /// isotropic plane-strain material, zero for plane stress and general Voigt input (plane
  /// bodies only).
  double out_of_plane_poisson = 0.0;

  /// 3 (plane) or 6 (solid): the length of the stress and strain vectors.
  int voigt_size() const { return static_cast<int>(stiffness.rows()); }
  /// 2 for a plane material, 3 for a solid one.
  int dimension() const { return voigt_size() == 6 ? 3 : 2; }
};

/// Isotropic plane material. Throws InputError (message prefixed by `context`, e.g.
/// "case.toml: body 'upper': material") when young <= 0 or poisson outside (-1, 0.5).
Material make_isotropic_material(double young, double poisson, PlaneModel model,
                                 const std::string& context);

/// Isotropic solid material: C = lambda 1 1' + 2 mu I on the normal components, mu on the shear
/// ones (engineering strain), lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)).
/// Throws as make_isotropic_material.
Material make_isotropic_solid_material(double young, double poisson, const std::string& context);

/// General symmetric Voigt stiffness, 3 x 3 (a plane material, `model` kept for its
/// out-of-plane stress, which is zero) or 6 x 6 (a solid one; `model` ignored). Throws
/// InputError when C has another size, is not symmetric (relative 1e-12) or not positive
/// definite.
Material make_voigt_material(const Eigen::MatrixXd& stiffness, PlaneModel model,
                             const std::string& context);

/// The full stress tensor of a Voigt stress of `material` (3 or 6 values); for a plane
/// material YZ = XZ = 0 and ZZ = out_of_plane_poisson (s_xx + s_yy).
StressTensor stress_tensor(const Material& material,
                           const Eigen::Ref<const Eigen::VectorXd>& voigt_stress);

/// Von Mises stress of a stress tensor (XX, YY, ZZ, XY, YZ, XZ).
double von_mises(const StressTensor& stress);

/// Von Mises stress of a Voigt stress of `material` (of its full tensor, stress_tensor).
double von_mises(const Material& material, const Eigen::Ref<const Eigen::VectorXd>& voigt_stress);

}  // namespace robin
