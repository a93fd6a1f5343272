#include "numerics/material.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <sstream>

#include "numerics/errors.hpp"

namespace robin {

namespace {

std::string format_number(double value) {
  std::ostringstream stream;
  stream.precision(12);
  stream << value;
  return stream.str();
}

void check_isotropic_parameters(double young, double poisson, const std::string& context) {
  if (!std::isfinite(young) || young <= 0.0) {
    throw InputError(context + ": Young's modulus " + format_number(young) +
                     " is not > 0: give a positive stiffness");
  }
  if (!std::isfinite(poisson)) {
    throw InputError(context + ": Poisson ratio " + format_number(poisson) + " is not a number");
  }
  if (poisson >= 0.5) {
    throw InputError(context + ": Poisson ratio " + format_number(poisson) +
                     " is not < 0.5: the material is incompressible or worse, which "
                     "displacement-based elements cannot represent; use a value below 0.5");
  }
  if (poisson <= -1.0) {
    throw InputError(context + ": Poisson ratio " + format_number(poisson) +
                     " is not > -1: the material would not be stable; use a value in (-1, 0.5)");
  }
}

}  // namespace

Material make_isotropic_material(double young, double poisson, PlaneModel model,
                                 const std::string& context) {
  check_isotropic_parameters(young, poisson, context);
  Material material;
  material.model = model;
  const double nu = poisson;
  if (model == PlaneModel::plane_strain) {
    // C = E / ((1 + nu)(1 - 2 nu)) [[1 - nu, nu, 0], [nu, 1 - nu, 0], [0, 0, (1 - 2 nu) / 2]]
    const double factor = young / ((1.0 + nu) * (1.0 - 2.0 * nu));
    material.stiffness << 1.0 - nu, nu, 0.0, nu, 1.0 - nu, 0.0, 0.0, 0.0, 0.5 * (1.0 - 2.0 * nu);
    material.stiffness *= factor;
    material.out_of_plane_poisson = nu;
  } else {
    // C = E / (1 - nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]]
    const double factor = young / (1.0 - nu * nu);
    material.stiffness << 1.0, nu, 0.0, nu, 1.0, 0.0, 0.0, 0.0, 0.5 * (1.0 - nu);
    material.stiffness *= factor;
    material.out_of_plane_poisson = 0.0;
  }
  return material;
}

Material make_voigt_material(const Eigen::Matrix3d& stiffness, PlaneModel model,
                             const std::string& context) {
  if (!stiffness.allFinite()) {
    throw InputError(context + ": the Voigt stiffness matrix has non-finite entries");
  }
  const double scale = stiffness.cwiseAbs().maxCoeff();
  const double asymmetry = (stiffness - stiffness.transpose()).cwiseAbs().maxCoeff();
  if (scale == 0.0 || asymmetry > 1e-12 * scale) {
    throw InputError(context +
                     ": the Voigt stiffness matrix is not symmetric (largest |C_ij - C_ji| = " +
                     format_number(asymmetry) + "): give C_ij = C_ji");
  }
  const Eigen::Matrix3d symmetric = 0.5 * (stiffness + stiffness.transpose());
  const Eigen::Vector3d eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(symmetric, Eigen::EigenvaluesOnly)
          .eigenvalues();
  if (eigenvalues(0) <= 1e-12 * eigenvalues(2)) {
    throw InputError(context +
                     ": the Voigt stiffness matrix is not positive definite (smallest eigenvalue " +
                     format_number(eigenvalues(0)) + ", largest " + format_number(eigenvalues(2)) +
                     "): the material would not be stable");
  }
  Material material;
  material.stiffness = symmetric;
  material.model = model;
  material.out_of_plane_poisson = 0.0;
  return material;
}

double von_mises(const Eigen::Vector3d& stress, double stress_zz) {
  // sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 s_xy^2)
  const double xx = stress(0);
  const double yy = stress(1);
  const double xy = stress(2);
  const double deviatoric = (xx - yy) * (xx - yy) + (yy - stress_zz) * (yy - stress_zz) +
                            (stress_zz - xx) * (stress_zz - xx);
  return std::sqrt(0.5 * deviatoric + 3.0 * xy * xy);
}

double out_of_plane_stress(const Material& material, const Eigen::Vector3d& stress) {
  return material.out_of_plane_poisson * (stress(0) + stress(1));
}

double von_mises(const Material& material, const Eigen::Vector3d& stress) {
  return von_mises(stress, out_of_plane_stress(material, stress));
}

}  // namespace robin
