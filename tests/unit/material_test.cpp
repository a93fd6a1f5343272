// Materials: isotropic plane strain and plane stress matrices against the Lame constants and
// the inverted compliance, validation errors, von Mises values known in closed form.

#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <limits>
#include <string>

#include "numerics/errors.hpp"
#include "numerics/material.hpp"

namespace robin {
namespace {

template <typename Call>
std::string input_error_message(Call&& call) {
  try {
    call();
  } catch (const InputError& error) {
    return error.what();
  }
  return "";
}

TEST(Material, PlaneStrainMatchesLameConstants) {
  const double young = 210.0, poisson = 0.3;
  const Material material =
      make_isotropic_material(young, poisson, PlaneModel::plane_strain, "steel");
  // lambda = E nu / ((1 + nu)(1 - 2 nu)), mu = E / (2 (1 + nu)); C = [[l + 2m, l, 0], [l, l + 2m,
  // 0], [0, 0, m]].
  const double lambda = young * poisson / ((1 + poisson) * (1 - 2 * poisson));
  const double mu = young / (2 * (1 + poisson));
  const Eigen::Matrix3d expected{
      {lambda + 2 * mu, lambda, 0.0}, {lambda, lambda + 2 * mu, 0.0}, {0.0, 0.0, mu}};
  EXPECT_LT((material.stiffness - expected).norm(), 1e-12 * expected.norm());
  EXPECT_EQ(material.model, PlaneModel::plane_strain);
  EXPECT_EQ(material.out_of_plane_poisson, poisson);
}

TEST(Material, PlaneStressIsTheInverseOfTheCompliance) {
  const double young = 70.0, poisson = 0.33;
  const Material material =
      make_isotropic_material(young, poisson, PlaneModel::plane_stress, "aluminium");
  // strain = S stress with S = [[1, -nu, 0], [-nu, 1, 0], [0, 0, 2 (1 + nu)]] / E.
  const Eigen::Matrix3d compliance =
      Eigen::Matrix3d{{1.0, -poisson, 0.0}, {-poisson, 1.0, 0.0}, {0.0, 0.0, 2 * (1 + poisson)}} /
      young;
  EXPECT_LT((material.stiffness * compliance - Eigen::Matrix3d::Identity()).norm(), 1e-13);
  EXPECT_EQ(material.out_of_plane_poisson, 0.0);
}

TEST(Material, InvalidIsotropicParametersAreInputErrorsWithContext) {
  const std::string context = "case.toml: body 'upper': material";
  const auto message = [&](double young, double poisson) {
    return input_error_message(
        [&] { make_isotropic_material(young, poisson, PlaneModel::plane_strain, context); });
  };
  for (const double young : {0.0, -5.0, std::numeric_limits<double>::quiet_NaN()}) {
    const std::string text = message(young, 0.3);
    EXPECT_EQ(text.rfind(context + ": Young's modulus", 0), 0u) << text;
  }
  const std::string incompressible = message(1.0, 0.5);
  EXPECT_EQ(incompressible.rfind(context + ": Poisson ratio 0.5 is not < 0.5", 0), 0u)
      << incompressible;
  EXPECT_NE(incompressible.find("incompressible"), std::string::npos) << incompressible;
  EXPECT_NE(message(1.0, 0.7).find("Poisson ratio 0.7"), std::string::npos);
  EXPECT_NE(message(1.0, -1.0).find("Poisson ratio -1 is not > -1"), std::string::npos);
  EXPECT_EQ(message(1.0, 0.49), "");
  EXPECT_EQ(message(1.0, -0.9), "");
}

TEST(Material, VoigtMatrixMustBeSymmetricPositiveDefinite) {
  const Eigen::Matrix3d valid{{300.0, 90.0, 25.0}, {90.0, 180.0, -15.0}, {25.0, -15.0, 70.0}};
  const Material material = make_voigt_material(valid, PlaneModel::plane_stress, "body");
  EXPECT_EQ(material.stiffness, valid);
  EXPECT_EQ(material.out_of_plane_poisson, 0.0);

  Eigen::Matrix3d asymmetric = valid;
  asymmetric(0, 1) += 1.0;
  std::string text = input_error_message(
      [&] { make_voigt_material(asymmetric, PlaneModel::plane_strain, "body 'lower'"); });
  EXPECT_EQ(text.rfind("body 'lower': ", 0), 0u) << text;
  EXPECT_NE(text.find("not symmetric"), std::string::npos) << text;

  // Eigenvalues 1, 3 and -2 (block [[2, 1], [1, 2]] and -2).
  const Eigen::Matrix3d indefinite{{2.0, 1.0, 0.0}, {1.0, 2.0, 0.0}, {0.0, 0.0, -2.0}};
  text = input_error_message(
      [&] { make_voigt_material(indefinite, PlaneModel::plane_strain, "body 'lower'"); });
  EXPECT_NE(text.find("not positive definite"), std::string::npos) << text;
  EXPECT_NE(text.find("smallest eigenvalue -2"), std::string::npos) << text;
}

TEST(Material, VonMisesOfClassicalStates) {
  // Uniaxial tension: sigma; pure shear tau: sqrt(3) tau; hydrostatic: 0.
  // (XX, YY, ZZ, XY, YZ, XZ)
  EXPECT_NEAR(von_mises(StressTensor{5.0, 0.0, 0.0, 0.0, 0.0, 0.0}), 5.0, 1e-14);
  EXPECT_NEAR(von_mises(StressTensor{0.0, 0.0, 0.0, 2.0, 0.0, 0.0}), 2.0 * std::sqrt(3.0), 1e-14);
  EXPECT_NEAR(von_mises(StressTensor{-4.0, -4.0, -4.0, 0.0, 0.0, 0.0}), 0.0, 1e-14);
  // Plane strain, nu = 0.3: s = (1, 1, 0) gives s_zz = 0.6 and
  // sqrt(((1 - 1)^2 + (1 - 0.6)^2 + (0.6 - 1)^2) / 2) = 0.4.
  const Material strain = make_isotropic_material(1.0, 0.3, PlaneModel::plane_strain, "m");
  EXPECT_NEAR(stress_tensor(strain, Eigen::Vector3d(1.0, 1.0, 0.0))(2), 0.6, 1e-15);
  EXPECT_NEAR(von_mises(strain, Eigen::Vector3d(1.0, 1.0, 0.0)), 0.4, 1e-14);
  // Plane stress: s_zz = 0, equal biaxial stress 1 gives 1.
  const Material stress = make_isotropic_material(1.0, 0.3, PlaneModel::plane_stress, "m");
  EXPECT_NEAR(von_mises(stress, Eigen::Vector3d(1.0, 1.0, 0.0)), 1.0, 1e-14);
}

}  // namespace
}  // namespace robin
