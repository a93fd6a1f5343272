// The members of BodySolver that only a floating body uses (body_solver.hpp, "Floating bodies"):
// the checks that contact can hold it and its local contact problem with the equality
// G lambda = h, solved by SMALBE-M.

#include <Eigen/SVD>
#include <chrono>
#include <cmath>
#include <sstream>

#include "numerics/body_solver.hpp"
#include "numerics/errors.hpp"
#include "numerics/nonnegative_least_squares.hpp"
#include "numerics/smalbe.hpp"

namespace robin {
namespace {

/// The relative size below which a singular value of B R counts as zero.
constexpr double sliding_tolerance = 1e-8;
/// The relative residual ||G lambda - h|| / ||h|| of the best lambda >= 0 above which the
/// equality counts as unsolvable.
constexpr double balance_tolerance = 1e-8;

std::string format_number(double value) {
  std::ostringstream text;
  text.precision(3);
  text << value;
  return text.str();
}

/// "(u_x, u_y, rotation) ~ (a, b, c)" (3D: u_x, u_y, u_z, rotation x, y, z) for the rigid motion
/// `motion` (free dofs): its least-squares coefficients on the rigid modes about the centre
/// (dof_map.hpp, rigid_mode_row), scaled so that the largest in magnitude is 1.
std::string describe_rigid_motion(const Mesh& mesh, const DofMap& dofs,
                                  const Eigen::VectorXd& motion) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& node : mesh.nodes) centre += node;
  centre /= static_cast<double>(mesh.node_count());
  const int count = rigid_mode_count(mesh.dimension);
  Eigen::MatrixXd normal = Eigen::MatrixXd::Zero(count, count);
  Eigen::VectorXd projection = Eigen::VectorXd::Zero(count);
  for (int dof = 0; dof < dofs.total_count(); ++dof) {
    if (dofs.is_prescribed(dof)) continue;
    const Eigen::VectorXd row = rigid_mode_row(mesh, dof, centre);
    normal += row * row.transpose();
    projection += row * motion[dofs.free_index(dof)];
  }
  Eigen::VectorXd coefficients = normal.ldlt().solve(projection);
  Eigen::Index largest = 0;
  coefficients.cwiseAbs().maxCoeff(&largest);
  coefficients /= coefficients[largest];  // the largest coefficient 1
  for (double& value : coefficients) {
    if (std::abs(value) < 1e-9) value = 0.0;
  }
  const std::string names = mesh.dimension == 3
                                ? "(u_x, u_y, u_z, rotation x, rotation y, rotation z)"
                                : "(u_x, u_y, rotation)";
  std::string values;
  for (Eigen::Index k = 0; k < coefficients.size(); ++k) {
    values += (k == 0 ? "" : ", ") + format_number(coefficients[k]);
  }
  return names + " ~ (" + values + ")";
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

Eigen::VectorXd BodySolver::rigid_load() const {
  // h = R'f (R' K_fp u_p = 0: K R = 0 on the whole mesh and R vanishes on prescribed dofs)
  return load_factor_ * (rigid_modes().transpose() * reduced_load_);
}

void BodySolver::check_held_by_contact() const {
  const int count = rigid_mode_count();
  if (count == 0) return;
  const std::string floating = "body '" + name() +
                               "' is a floating body (its Dirichlet "
                               "conditions leave " +
                               std::to_string(count) + " rigid motions free)";
  // (a) B R of full column rank: every rigid motion moves some contact row.
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(rigid_trace_, Eigen::ComputeFullV);
  const Eigen::VectorXd& singular = svd.singularValues();
  if (rigid_trace_.rows() < count || !(singular[count - 1] > sliding_tolerance * singular[0])) {
    const Eigen::VectorXd motion = rigid_modes() * svd.matrixV().col(count - 1);
    throw SingularBodyError(floating + " with a free sliding direction: the rigid motion " +
                            describe_rigid_motion(mesh(), dofs(), motion) +
                            " moves none of its contact rows, so contact cannot hold it; add a "
                            "Dirichlet condition that removes this motion");
  }
  // (b) G lambda = h with lambda >= 0: compressive contact forces can balance the loads.
  const Eigen::VectorXd load = rigid_load();
  const NonnegativeLeastSquaresResult balance =
      solve_nonnegative_least_squares(rigid_trace_.transpose(), load);
  if (balance.residual_norm > balance_tolerance * load.norm()) {
    throw SingularBodyError(floating +
                            ": the loads push the body away from every contact: no "
                            "compressive contact forces on its contact rows balance the loads "
                            "along its free rigid motions (unbalanced " +
                            format_number(balance.residual_norm / load.norm() * 100.0) +
                            "% of the load); a floating body is held by contact alone");
  }
}

ContactSolveResult BodySolver::solve_floating_contact(const Eigen::VectorXd& obstacle,
                                                      const MprgpParameters& parameters) {
  const auto start = std::chrono::steady_clock::now();
  check_held_by_contact();  // the load factor may have changed the balance
  // minimise 1/2 l'F l - l'(e - g) s.t. l >= 0, G l = h
  const Eigen::VectorXd right_hand_side = free_trace_ - obstacle;
  const Eigen::VectorXd lower = Eigen::VectorXd::Zero(contact_size());
  SmalbeParameters smalbe;
  smalbe.relative_tolerance = parameters.relative_tolerance;
  smalbe.max_iterations = parameters.max_iterations;
  smalbe.operator_norm = parameters.operator_norm;
  const SmalbeResult qp =
      solve_smalbe(*compliance_, right_hand_side, lower, rigid_trace_.transpose(), rigid_load(),
                   warm_start_, warm_multiplier_, smalbe);
  // u_N = g - (F l - (e - g) + G'mu) = e - F l + B R alpha with alpha = -mu
  ContactSolveResult result = contact_solve_result(qp, obstacle);
  if (qp.status == QpStatus::converged) {
    warm_start_ = qp.solution;
    warm_multiplier_ = qp.multiplier;
    rigid_amplitudes_ = -qp.multiplier;
  }
  result.seconds = seconds_since(start);
  return result;
}

}  // namespace robin
