#include "coupling/coupling_scheme.hpp"

#include <algorithm>
#include <array>
#include <numeric>

#include <Eigen/Eigenvalues>

#include "numerics/errors.hpp"

namespace robin {
namespace {

int count_active(const ContactSolveResult& result) {
  return static_cast<int>(std::count(result.active.begin(), result.active.end(), true));
}

void require_converged(const ContactSolveResult& result, const SubdomainPort& port, int iteration) {
  if (result.status == QpStatus::converged) return;
  throw PortError(port.describe() + ", step contact solve (iteration " + std::to_string(iteration) +
                  "): the contact QP returned '" + to_string(result.status) +
                  "': " + result.message);
}

/// Step 1 on both bodies in parallel: u^a = argmin 1/2 u'K^a u - f^a'u s.t. B^a u <= g^a.
std::array<ContactSolveResult, 2> contact_solves(SubdomainPort& body1, SubdomainPort& body2,
                                                 const Eigen::VectorXd& obstacle1,
                                                 const Eigen::VectorXd& obstacle2, int iteration) {
  body1.start_contact_solve(obstacle1, iteration);
  body2.start_contact_solve(obstacle2, iteration);
  std::array<ContactSolveResult, 2> results{body1.finish_contact_solve(),
                                            body2.finish_contact_solve()};
  require_converged(results[0], body1, iteration);
  require_converged(results[1], body2, iteration);
  return results;
}

/// Correction solves on both bodies in parallel: w^a_N = F^a r^a.
std::array<CorrectionSolveResult, 2> correction_solves(SubdomainPort& body1, SubdomainPort& body2,
                                                       const Eigen::VectorXd& force1,
                                                       const Eigen::VectorXd& force2,
                                                       int iteration) {
  body1.start_correction(force1, iteration);
  body2.start_correction(force2, iteration);
  return {body1.finish_correction(), body2.finish_correction()};
}

/// Step 1 on both bodies at the obstacles already in evaluation.state; fills the state's
/// traces and forces and the evaluation's counters.
void solve_both_contacts(SubdomainPort& body1, SubdomainPort& body2, int iteration,
                         CouplingEvaluation& evaluation) {
  CouplingState& state = evaluation.state;
  const auto contact = contact_solves(body1, body2, state.obstacle1, state.obstacle2, iteration);
  state.normal_trace1 = contact[0].normal_trace;
  state.normal_trace2 = contact[1].normal_trace;
  state.contact_force1 = contact[0].contact_force;
  state.contact_force2 = contact[1].contact_force;
  evaluation.active1 = count_active(contact[0]);
  evaluation.active2 = count_active(contact[1]);
  evaluation.qp_iterations1 = contact[0].iterations;
  evaluation.qp_iterations2 = contact[1].iterations;
  evaluation.critical_compute_seconds += std::max(contact[0].seconds, contact[1].seconds);
}

/// "robin" and "robin-constant" (alpha > 0): two obstacle sequences.
class RobinScheme final : public CouplingScheme {
 public:
  RobinScheme(SubdomainPort& body1, SubdomainPort& body2, Eigen::VectorXd gaps,
              Eigen::VectorXd weights, double constant_alpha)
      : body1_(body1),
        body2_(body2),
        gaps_(std::move(gaps)),
        weights_(std::move(weights)),
        constant_alpha_(constant_alpha) {}

  std::vector<int> block_sizes() const override {
    const int size = static_cast<int>(gaps_.size());
    if (constant_alpha_ > 0.0) return {2 * size};  // H^1 depends on g^2 through lambda^2
    return {size, size};
  }
  std::string describe() const override {
    return constant_alpha_ > 0.0
               ? "robin-constant (alpha = " + std::to_string(constant_alpha_) + ")"
               : std::string("robin");
  }
  Eigen::VectorXd initial_iterate(const Eigen::VectorXd& initial_obstacle) const override {
    Eigen::VectorXd iterate(2 * gaps_.size());
    iterate << initial_obstacle, initial_obstacle;
    return iterate;
  }

  void repeat_contact_solves(const Eigen::VectorXd& iterate, int iteration) override {
    const Eigen::Index size = gaps_.size();
    contact_solves(body1_, body2_, iterate.head(size), iterate.tail(size), iteration);
  }

  CouplingEvaluation evaluate(const Eigen::VectorXd& iterate, int iteration) override {
    const Eigen::Index size = gaps_.size();
    CouplingEvaluation evaluation;
    CouplingState& state = evaluation.state;
    state.obstacle1 = iterate.head(size);
    state.obstacle2 = iterate.tail(size);
    solve_both_contacts(body1_, body2_, iteration, evaluation);
    // Step 2: K^1 w^1 = B^1'(lambda^2 - lambda^1), K^2 w^2 = B^2'(lambda^1 - lambda^2), or the
    // constant-alpha stand-in alpha (lambda^b - lambda^a) / m for w^a_N.
    const Eigen::VectorXd imbalance = state.contact_force2 - state.contact_force1;
    if (constant_alpha_ > 0.0) {
      state.correction1 = constant_alpha_ * imbalance.cwiseQuotient(weights_);
      state.correction2 = -state.correction1;
    } else {
      const auto correction = correction_solves(body1_, body2_, imbalance, -imbalance, iteration);
      state.correction1 = correction[0].normal_trace;
      state.correction2 = correction[1].normal_trace;
      evaluation.critical_compute_seconds += std::max(correction[0].seconds, correction[1].seconds);
      evaluation.completions = {completion(state, 1), completion(state, 2)};
    }
    // Step 3's map: H = (w2_N - u2_N + d, w1_N - u1_N + d).
    evaluation.mapped.resize(2 * size);
    evaluation.mapped << state.correction2 - state.normal_trace2 + gaps_,
        state.correction1 - state.normal_trace1 + gaps_;
    return evaluation;
  }

 private:
  /// The complete state of obstacle sequence `sequence`: its body's contact force on both
  /// bodies, the other body's trace u_N - w_N = e - F lambda.
  static CouplingState completion(const CouplingState& state, int sequence) {
    CouplingState complete = state;
    if (sequence == 1) {
      complete.normal_trace2 = state.normal_trace2 - state.correction2;
      complete.contact_force2 = state.contact_force1;
    } else {
      complete.normal_trace1 = state.normal_trace1 - state.correction1;
      complete.contact_force1 = state.contact_force2;
    }
    complete.correction1.setZero();
    complete.correction2.setZero();
    return complete;
  }

  SubdomainPort& body1_;
  SubdomainPort& body2_;
  const Eigen::VectorXd gaps_;
  const Eigen::VectorXd weights_;
  const double constant_alpha_;  // 0: the Steklov-Poincare choice (correction solves)
};

/// "dirichlet-neumann": one obstacle sequence, for the contact body.
class DirichletNeumannScheme final : public CouplingScheme {
 public:
  /// `contact_body` 0 or 1: the body that solves the contact problem.
  DirichletNeumannScheme(SubdomainPort& body1, SubdomainPort& body2, Eigen::VectorXd gaps,
                         int contact_body)
      : contact_port_(contact_body == 0 ? body1 : body2),
        neumann_port_(contact_body == 0 ? body2 : body1),
        gaps_(std::move(gaps)),
        contact_body_(contact_body) {}

  std::vector<int> block_sizes() const override { return {static_cast<int>(gaps_.size())}; }
  bool shares_contact_force() const override { return true; }
  std::string describe() const override {
    return "dirichlet-neumann (contact body " + std::to_string(contact_body_ + 1) +
           ", Neumann body " + std::to_string(2 - contact_body_) + ")";
  }
  Eigen::VectorXd initial_iterate(const Eigen::VectorXd& initial_obstacle) const override {
    return initial_obstacle;
  }

  void repeat_contact_solves(const Eigen::VectorXd& iterate, int iteration) override {
    contact_port_.start_contact_solve(iterate, iteration);
    require_converged(contact_port_.finish_contact_solve(), contact_port_, iteration);
  }

  CouplingEvaluation evaluate(const Eigen::VectorXd& iterate, int iteration) override {
    contact_port_.start_contact_solve(iterate, iteration);
    const ContactSolveResult contact = contact_port_.finish_contact_solve();
    require_converged(contact, contact_port_, iteration);
    neumann_port_.start_neumann_solve(contact.contact_force, iteration);
    const CorrectionSolveResult neumann = neumann_port_.finish_neumann_solve();
    CouplingEvaluation evaluation;
    evaluation.critical_compute_seconds = contact.seconds + neumann.seconds;
    const int active = count_active(contact);
    (contact_body_ == 0 ? evaluation.active1 : evaluation.active2) = active;
    (contact_body_ == 0 ? evaluation.qp_iterations1 : evaluation.qp_iterations2) =
        contact.iterations;
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(gaps_.size());
    const Eigen::VectorXd other_obstacle = gaps_ - iterate;
    CouplingState& state = evaluation.state;
    state.obstacle1 = contact_body_ == 0 ? iterate : other_obstacle;
    state.obstacle2 = contact_body_ == 0 ? other_obstacle : iterate;
    state.normal_trace1 = contact_body_ == 0 ? contact.normal_trace : neumann.normal_trace;
    state.normal_trace2 = contact_body_ == 0 ? neumann.normal_trace : contact.normal_trace;
    state.contact_force1 = contact.contact_force;
    state.contact_force2 = contact.contact_force;
    state.correction1 = zero;
    state.correction2 = zero;
    evaluation.mapped = gaps_ - neumann.normal_trace;  // H = d - u^N_N
    return evaluation;
  }

 private:
  SubdomainPort& contact_port_;
  SubdomainPort& neumann_port_;
  const Eigen::VectorXd gaps_;
  const int contact_body_;
};

/// "neumann-neumann": one sequence, the share g1 of the gap given to body 1.
class NeumannNeumannScheme final : public CouplingScheme {
 public:
  NeumannNeumannScheme(SubdomainPort& body1, SubdomainPort& body2, Eigen::VectorXd gaps)
      : body1_(body1), body2_(body2), gaps_(std::move(gaps)) {}

  std::vector<int> block_sizes() const override { return {static_cast<int>(gaps_.size())}; }
  std::string describe() const override { return "neumann-neumann"; }
  /// Body 1 starts with half of the initial obstacle, so that g1 + g2 = d from the start when
  /// the initial obstacle is the gap.
  Eigen::VectorXd initial_iterate(const Eigen::VectorXd& initial_obstacle) const override {
    return 0.5 * initial_obstacle;
  }

  void repeat_contact_solves(const Eigen::VectorXd& iterate, int iteration) override {
    contact_solves(body1_, body2_, iterate, gaps_ - iterate, iteration);
  }

  CouplingEvaluation evaluate(const Eigen::VectorXd& iterate, int iteration) override {
    CouplingEvaluation evaluation;
    CouplingState& state = evaluation.state;
    state.obstacle1 = iterate;
    state.obstacle2 = gaps_ - iterate;
    solve_both_contacts(body1_, body2_, iteration, evaluation);
    // Both bodies loaded by the force jump j = lambda1 - lambda2 along their outward normal.
    const Eigen::VectorXd jump = state.contact_force1 - state.contact_force2;
    const auto correction = correction_solves(body1_, body2_, jump, jump, iteration);
    state.correction1 = correction[0].normal_trace;
    state.correction2 = correction[1].normal_trace;
    evaluation.critical_compute_seconds += std::max(correction[0].seconds, correction[1].seconds);
    evaluation.mapped = iterate + 0.25 * (state.correction1 + state.correction2);
    return evaluation;
  }

 private:
  SubdomainPort& body1_;
  SubdomainPort& body2_;
  const Eigen::VectorXd gaps_;
};

/// "auto": the body that is more compliant at short wavelengths takes the obstacle.
int more_compliant_body(SubdomainPort& body1, SubdomainPort& body2,
                        const Eigen::VectorXd& probe_forces) {
  const auto response = correction_solves(body1, body2, probe_forces, probe_forces, 0);
  const double compliance1 = probe_forces.dot(response[0].normal_trace);
  const double compliance2 = probe_forces.dot(response[1].normal_trace);
  return compliance1 >= compliance2 ? 0 : 1;
}

}  // namespace

Eigen::VectorXd short_wavelength_forces(const ContactPairing& pairing) {
  const std::size_t size = pairing.size();
  Eigen::VectorXd forces = pairing.weights();
  if (size < 2) return forces;
  // Principal direction t of the pair positions; the pairs ranked by t . x alternate in sign.
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const ContactPair& pair : pairing.pairs) mean += pair.position / static_cast<double>(size);
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const ContactPair& pair : pairing.pairs) {
    scatter += (pair.position - mean) * (pair.position - mean).transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
  const Eigen::Vector2d direction = eigen.eigenvectors().col(1);  // largest eigenvalue
  std::vector<std::size_t> order(size);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return direction.dot(pairing.pairs[a].position) < direction.dot(pairing.pairs[b].position);
  });
  for (std::size_t rank = 1; rank < size; rank += 2) {
    forces[static_cast<Eigen::Index>(order[rank])] *= -1.0;
  }
  return forces;
}

std::unique_ptr<CouplingScheme> make_coupling_scheme(const CouplingOptions& options,
                                                     SubdomainPort& body1, SubdomainPort& body2,
                                                     const Eigen::VectorXd& gaps,
                                                     const Eigen::VectorXd& weights,
                                                     const Eigen::VectorXd& probe_forces) {
  if (options.algorithm == "robin") {
    return std::make_unique<RobinScheme>(body1, body2, gaps, weights, 0.0);
  }
  if (options.algorithm == "robin-constant") {
    if (!(options.alpha > 0.0)) {
      throw InputError("coupling.alpha must be > 0 for the algorithm \"robin-constant\"");
    }
    if (weights.size() != gaps.size() || (weights.array() <= 0.0).any()) {
      throw InputError(
          "the algorithm \"robin-constant\" needs a positive boundary weight per pair");
    }
    return std::make_unique<RobinScheme>(body1, body2, gaps, weights, options.alpha);
  }
  if (options.algorithm == "dirichlet-neumann") {
    const int contact_body = options.contact_body == "1" ? 0
                             : options.contact_body == "2"
                                 ? 1
                                 : more_compliant_body(body1, body2, probe_forces);
    return std::make_unique<DirichletNeumannScheme>(body1, body2, gaps, contact_body);
  }
  if (options.algorithm == "neumann-neumann") {
    return std::make_unique<NeumannNeumannScheme>(body1, body2, gaps);
  }
  throw InputError(
      "coupling.algorithm must be \"robin\", \"robin-constant\", "
      "\"dirichlet-neumann\" or \"neumann-neumann\", got \"" +
      options.algorithm + "\"");
}

}  // namespace robin
