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
  material.stiffness.resize(3, 3);
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

Material make_isotropic_solid_material(double young, double poisson, const std::string& context) {
  check_isotropic_parameters(young, poisson, context);
  const double lambda = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
  const double mu = young / (2.0 * (1.0 + poisson));
  Material material;
  material.stiffness = Eigen::MatrixXd::Zero(6, 6);
  material.stiffness.topLeftCorner(3, 3).setConstant(lambda);
  for (int i = 0; i < 3; ++i) {
    material.stiffness(i, i) += 2.0 * mu;
    material.stiffness(3 + i, 3 + i) = mu;
  }
  return material;
}

Material make_voigt_material(const Eigen::MatrixXd& stiffness, PlaneModel model,
                             const std::string& context) {
  if (!((stiffness.rows() == 3 && stiffness.cols() == 3) ||
        (stiffness.rows() == 6 && stiffness.cols() == 6))) {
    throw InputError(context + ": the Voigt stiffness matrix is " +
                     std::to_string(stiffness.rows()) + " x " + std::to_string(stiffness.cols()) +
                     ": give 3 x 3 (plane) or 6 x 6 (solid)");
  }
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
  const Eigen::MatrixXd symmetric = 0.5 * (stiffness + stiffness.transpose());
  const Eigen::VectorXd eigenvalues =
      Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(symmetric, Eigen::EigenvaluesOnly)
          .eigenvalues();
  const double largest = eigenvalues(eigenvalues.size() - 1);
  if (eigenvalues(0) <= 1e-12 * largest) {
    throw InputError(context +
                     ": the Voigt stiffness matrix is not positive definite (smallest eigenvalue " +
                     format_number(eigenvalues(0)) + ", largest " + format_number(largest) +
                     "): the material would not be stable");
  }
  Material material;
  material.stiffness = symmetric;
  material.model = model;
  material.out_of_plane_poisson = 0.0;
  return material;
}

StressTensor stress_tensor(const Material& material,
                           const Eigen::Ref<const Eigen::VectorXd>& voigt_stress) {
  StressTensor tensor;
  if (material.voigt_size() == 6) {
    // Voigt (xx, yy, zz, yz, xz, xy) to (XX, YY, ZZ, XY, YZ, XZ).
    tensor << voigt_stress(0), voigt_stress(1), voigt_stress(2), voigt_stress(5), voigt_stress(3),
        voigt_stress(4);
    return tensor;
  }
  const double zz = material.out_of_plane_poisson * (voigt_stress(0) + voigt_stress(1));
  tensor << voigt_stress(0), voigt_stress(1), zz, voigt_stress(2), 0.0, 0.0;
  return tensor;
}

double von_mises(const StressTensor& stress) {
  // sqrt(((s_xx - s_yy)^2 + (s_yy - s_zz)^2 + (s_zz - s_xx)^2) / 2 + 3 (s_xy^2 + s_yz^2 + s_xz^2))
  const double xx = stress(0), yy = stress(1), zz = stress(2);
  const double deviatoric = (xx - yy) * (xx - yy) + (yy - zz) * (yy - zz) + (zz - xx) * (zz - xx);
  const double shear = stress(3) * stress(3) + stress(4) * stress(4) + stress(5) * stress(5);
  return std::sqrt(0.5 * deviatoric + 3.0 * shear);
}

double von_mises(const Material& material, const Eigen::Ref<const Eigen::VectorXd>& voigt_stress) {
  return von_mises(stress_tensor(material, voigt_stress));
}

}  // namespace robin
