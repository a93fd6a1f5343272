#include "coupling/coupling_scheme.hpp"

#include <algorithm>
#include <array>
#include <numeric>
#include <optional>
#include <stdexcept>

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

/// Step 1 on every body in parallel: u^a = argmin 1/2 u'K^a u - f^a'u s.t. B^a u <= g^a.
std::vector<ContactSolveResult> contact_solves(const std::vector<SubdomainPort*>& ports,
                                               const std::vector<Eigen::VectorXd>& obstacles,
                                               int iteration) {
  for (std::size_t body = 0; body < ports.size(); ++body) {
    ports[body]->start_contact_solve(obstacles[body], iteration);
  }
  std::vector<ContactSolveResult> results;
  for (SubdomainPort* port : ports) results.push_back(port->finish_contact_solve());
  for (std::size_t body = 0; body < ports.size(); ++body) {
    require_converged(results[body], *ports[body], iteration);
  }
  return results;
}

/// Correction solves on every body in parallel: w^a_N = F^a r^a.
std::vector<CorrectionSolveResult> correction_solves(const std::vector<SubdomainPort*>& ports,
                                                     const std::vector<Eigen::VectorXd>& forces,
                                                     int iteration) {
  for (std::size_t body = 0; body < ports.size(); ++body) {
    ports[body]->start_correction(forces[body], iteration, 0.0);
  }
  std::vector<CorrectionSolveResult> results;
  for (SubdomainPort* port : ports) results.push_back(port->finish_correction());
  return results;
}

double slowest(const std::vector<double>& seconds) {
  return seconds.empty() ? 0.0 : *std::max_element(seconds.begin(), seconds.end());
}

/// Step 1 on every body at the obstacles already in evaluation.state; fills the state's
/// traces and forces and the evaluation's counters.
void solve_all_contacts(const std::vector<SubdomainPort*>& ports, int iteration,
                        CouplingEvaluation& evaluation) {
  std::vector<Eigen::VectorXd> obstacles;
  for (const BodyInterfaceState& body : evaluation.state.bodies) obstacles.push_back(body.obstacle);
  const std::vector<ContactSolveResult> contact = contact_solves(ports, obstacles, iteration);
  std::vector<double> seconds;
  for (std::size_t body = 0; body < ports.size(); ++body) {
    BodyInterfaceState& state = evaluation.state.bodies[body];
    state.normal_trace = contact[body].normal_trace;
    state.contact_force = contact[body].contact_force;
    evaluation.active.push_back(count_active(contact[body]));
    evaluation.qp_iterations.push_back(contact[body].iterations);
    seconds.push_back(contact[body].seconds);
  }
  evaluation.critical_compute_seconds += slowest(seconds);
}

/// "robin" and "robin-constant" (alpha > 0): one obstacle sequence per colour class.
class RobinScheme final : public CouplingScheme {
 public:
  /// The iterate x stacks the bodies' obstacles colour class by colour class (class 0's bodies
  /// in body order, then class 1's; body order on a graph with an odd cycle): H of a class reads
  /// only the contact solutions of the same class (H^a = -(e^b - F^b lambda^across(b)) + d with
  /// b a neighbour of a and across(b) of a's class), so each class is a block of its own.
  /// `colouring`: a 2-colouring of the graph, or nothing for a graph with an odd cycle.
  /// `frozen_class` (0 or 1, or -1 for none): the colour class whose obstacles stay at their
  /// initial values (H = x) because its sequence would need a floating body's Neumann response
  /// (coupling_scheme.hpp, "Floating bodies"); that class has no obstacle sequence.
  RobinScheme(std::vector<SubdomainPort*> ports, CouplingProblem problem, double constant_alpha,
              std::optional<std::vector<int>> colouring, int frozen_class)
      : ports_(std::move(ports)),
        problem_(std::move(problem)),
        constant_alpha_(constant_alpha),
        colouring_(std::move(colouring)),
        frozen_class_(frozen_class) {
    for (const int colour : {0, 1}) {
      ObstacleSequence sequence;
      for (int body = 0; body < problem_.graph.body_count(); ++body) {
        if ((colouring_ ? (*colouring_)[static_cast<std::size_t>(body)] : 0) == colour) {
          sequence.bodies.push_back(body);
          order_.push_back(body);
        }
      }
      if (sequence.bodies.empty()) continue;
      // robin-constant: one block (H^a depends on g^b through lambda^b); an odd cycle: one.
      sequence.blocks = {constant_alpha_ > 0.0 || !colouring_ ? 0 : colour};
      if (colouring_ && colour != frozen_class_) sequences_.push_back(sequence);
      Eigen::Index size = 0;
      for (const int body : sequence.bodies) size += problem_.graph.body_rows(body);
      if (sequence.blocks.front() == colour) {
        block_sizes_.push_back(static_cast<int>(size));
      } else {
        block_sizes_.front() += static_cast<int>(size);
      }
    }
  }

  std::vector<int> block_sizes() const override { return block_sizes_; }
  std::vector<ObstacleSequence> sequences() const override { return sequences_; }
  std::string describe() const override {
    if (constant_alpha_ > 0.0) {
      return "robin-constant (alpha = " + std::to_string(constant_alpha_) + ")";
    }
    return frozen_class_ < 0 ? std::string("robin")
                             : "robin (floating bodies: only the obstacle sequence of " +
                                   describe_bodies(sequences_.front().bodies) + ")";
  }
  Eigen::VectorXd initial_iterate(const Eigen::VectorXd& initial_obstacle) const override {
    std::vector<Eigen::VectorXd> parts;
    for (int body = 0; body < problem_.graph.body_count(); ++body) {
      parts.push_back(problem_.graph.body_part(body, initial_obstacle));
    }
    return stack(parts);
  }

  void repeat_contact_solves(const Eigen::VectorXd& iterate, int iteration) override {
    contact_solves(ports_, split(iterate), iteration);
  }

  CouplingEvaluation evaluate(const Eigen::VectorXd& iterate, int iteration) override {
    const ContactGraph& graph = problem_.graph;
    CouplingEvaluation evaluation;
    CouplingState& state = evaluation.state;
    state.bodies.resize(ports_.size());
    const std::vector<Eigen::VectorXd> obstacles = split(iterate);
    for (std::size_t body = 0; body < ports_.size(); ++body) {
      state.bodies[body].obstacle = obstacles[body];
    }
    solve_all_contacts(ports_, iteration, evaluation);
    // Step 2: K^a w^a = B^a'(lambda^across - lambda^a), or the constant-alpha stand-in
    // alpha (lambda^across - lambda^a) / m for w^a_N.
    const std::vector<Eigen::VectorXd> forces = state.contact_forces();
    std::vector<Eigen::VectorXd> imbalances;
    for (int body = 0; body < graph.body_count(); ++body) {
      imbalances.push_back(graph.across(body, forces) - forces[static_cast<std::size_t>(body)]);
    }
    if (constant_alpha_ > 0.0) {
      for (int body = 0; body < graph.body_count(); ++body) {
        state.bodies[static_cast<std::size_t>(body)].correction =
            constant_alpha_ * imbalances[static_cast<std::size_t>(body)].cwiseQuotient(
                                  graph.body_part(body, problem_.weights));
      }
    } else {
      const auto correction = correction_solves(ports_, imbalances, iteration);
      std::vector<double> seconds;
      for (std::size_t body = 0; body < ports_.size(); ++body) {
        state.bodies[body].correction = correction[body].normal_trace;
        seconds.push_back(correction[body].seconds);
      }
      evaluation.critical_compute_seconds += slowest(seconds);
      for (const ObstacleSequence& sequence : sequences()) {
        evaluation.completions.push_back(completion(state, sequence));
      }
    }
    // Step 3's map: H^a = (w_N - u_N)^across + d on each of body a's rows.
    std::vector<Eigen::VectorXd> sent;
    for (const BodyInterfaceState& body : state.bodies) {
      sent.push_back(body.correction - body.normal_trace);
    }
    std::vector<Eigen::VectorXd> mapped;
    for (int body = 0; body < graph.body_count(); ++body) {
      mapped.push_back(is_frozen(body) ? obstacles[static_cast<std::size_t>(body)]
                                       : Eigen::VectorXd(graph.across(body, sent) +
                                                         graph.body_part(body, problem_.gaps)));
    }
    evaluation.mapped = stack(mapped);
    return evaluation;
  }

 private:
  /// Per body (body order) its block of an iterate stacked in iterate order.
  std::vector<Eigen::VectorXd> split(const Eigen::VectorXd& iterate) const {
    std::vector<Eigen::VectorXd> parts(ports_.size());
    Eigen::Index offset = 0;
    for (const int body : order_) {
      const Eigen::Index size = problem_.graph.body_rows(body);
      parts[static_cast<std::size_t>(body)] = iterate.segment(offset, size);
      offset += size;
    }
    return parts;
  }
  /// Per-body vectors (body order) stacked in iterate order.
  Eigen::VectorXd stack(const std::vector<Eigen::VectorXd>& per_body) const {
    std::vector<Eigen::VectorXd> ordered;
    for (const int body : order_) ordered.push_back(per_body[static_cast<std::size_t>(body)]);
    return concatenate(ordered);
  }

  /// The complete state of `sequence`: its bodies keep (u, lambda); every other body (all its
  /// neighbours are in the sequence) takes lambda^across, its trace u_N - w_N = e - F lambda.
  CouplingState completion(const CouplingState& state, const ObstacleSequence& sequence) const {
    CouplingState complete = state;
    const std::vector<Eigen::VectorXd> forces = state.contact_forces();
    for (int body = 0; body < problem_.graph.body_count(); ++body) {
      BodyInterfaceState& target = complete.bodies[static_cast<std::size_t>(body)];
      const bool keeps =
          std::find(sequence.bodies.begin(), sequence.bodies.end(), body) != sequence.bodies.end();
      if (!keeps) {
        target.normal_trace = target.normal_trace - target.correction;
        target.contact_force = problem_.graph.across(body, forces);
      }
      target.correction.setZero();
    }
    return complete;
  }

  /// Whether `body`'s obstacles are frozen (its class's sequence is not well defined).
  bool is_frozen(int body) const {
    return colouring_ && frozen_class_ >= 0 &&
           (*colouring_)[static_cast<std::size_t>(body)] == frozen_class_;
  }

  const std::vector<SubdomainPort*> ports_;
  const CouplingProblem problem_;
  const double constant_alpha_;  // 0: the Steklov-Poincare choice (correction solves)
  const std::optional<std::vector<int>> colouring_;
  const int frozen_class_;
  std::vector<int> order_;  // the bodies in iterate order
  std::vector<int> block_sizes_;
  std::vector<ObstacleSequence> sequences_;
};

/// The two obstacle sequences of a two-body scheme with one block.
std::vector<ObstacleSequence> two_body_sequences() {
  return {{{0}, {0}}, {{1}, {0}}};
}

/// "dirichlet-neumann": one obstacle sequence, for the contact body.
class DirichletNeumannScheme final : public CouplingScheme {
 public:
  /// `contact_body` 0 or 1: the body that solves the contact problem.
  DirichletNeumannScheme(const std::vector<SubdomainPort*>& ports, Eigen::VectorXd gaps,
                         int contact_body)
      : contact_port_(*ports[static_cast<std::size_t>(contact_body)]),
        neumann_port_(*ports[static_cast<std::size_t>(1 - contact_body)]),
        gaps_(std::move(gaps)),
        contact_body_(contact_body) {}

  std::vector<int> block_sizes() const override { return {static_cast<int>(gaps_.size())}; }
  std::vector<ObstacleSequence> sequences() const override { return two_body_sequences(); }
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
    evaluation.active = {0, 0};
    evaluation.qp_iterations = {0, 0};
    evaluation.active[static_cast<std::size_t>(contact_body_)] = count_active(contact);
    evaluation.qp_iterations[static_cast<std::size_t>(contact_body_)] = contact.iterations;
    evaluation.state.bodies.resize(2);
    BodyInterfaceState& contact_state =
        evaluation.state.bodies[static_cast<std::size_t>(contact_body_)];
    BodyInterfaceState& neumann_state =
        evaluation.state.bodies[static_cast<std::size_t>(1 - contact_body_)];
    contact_state.obstacle = iterate;
    contact_state.normal_trace = contact.normal_trace;
    neumann_state.obstacle = gaps_ - iterate;
    neumann_state.normal_trace = neumann.normal_trace;
    for (BodyInterfaceState& body : evaluation.state.bodies) {
      body.contact_force = contact.contact_force;
      body.correction = Eigen::VectorXd::Zero(gaps_.size());
    }
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
  NeumannNeumannScheme(std::vector<SubdomainPort*> ports, Eigen::VectorXd gaps)
      : ports_(std::move(ports)), gaps_(std::move(gaps)) {}

  std::vector<int> block_sizes() const override { return {static_cast<int>(gaps_.size())}; }
  std::vector<ObstacleSequence> sequences() const override { return two_body_sequences(); }
  std::string describe() const override { return "neumann-neumann"; }
  /// Body 1 starts with half of the initial obstacle, so that g1 + g2 = d from the start when
  /// the initial obstacle is the gap.
  Eigen::VectorXd initial_iterate(const Eigen::VectorXd& initial_obstacle) const override {
    return 0.5 * initial_obstacle;
  }

  void repeat_contact_solves(const Eigen::VectorXd& iterate, int iteration) override {
    contact_solves(ports_, {iterate, gaps_ - iterate}, iteration);
  }

  CouplingEvaluation evaluate(const Eigen::VectorXd& iterate, int iteration) override {
    CouplingEvaluation evaluation;
    CouplingState& state = evaluation.state;
    state.bodies.resize(2);
    state.bodies[0].obstacle = iterate;
    state.bodies[1].obstacle = gaps_ - iterate;
    solve_all_contacts(ports_, iteration, evaluation);
    // Both bodies loaded by the force jump j = lambda1 - lambda2 along their outward normal.
    const Eigen::VectorXd jump = state.bodies[0].contact_force - state.bodies[1].contact_force;
    const auto correction = correction_solves(ports_, {jump, jump}, iteration);
    state.bodies[0].correction = correction[0].normal_trace;
    state.bodies[1].correction = correction[1].normal_trace;
    evaluation.critical_compute_seconds += std::max(correction[0].seconds, correction[1].seconds);
    evaluation.mapped = iterate + 0.25 * (state.bodies[0].correction + state.bodies[1].correction);
    return evaluation;
  }

 private:
  const std::vector<SubdomainPort*> ports_;
  const Eigen::VectorXd gaps_;
};

/// "auto": the body that is more compliant at short wavelengths takes the obstacle.
int more_compliant_body(const std::vector<SubdomainPort*>& ports, const CouplingProblem& problem) {
  const Eigen::VectorXd& probe = problem.probe_forces;
  std::vector<Eigen::VectorXd> responses = problem.probe_responses;
  if (responses.size() != 2) {
    for (const CorrectionSolveResult& response : correction_solves(ports, {probe, probe}, 0)) {
      responses.push_back(response.normal_trace);
    }
  }
  return probe.dot(responses[0]) >= probe.dot(responses[1]) ? 0 : 1;
}

/// Throws InputError unless the graph is two bodies with one interface.
void require_two_bodies(const CouplingOptions& options, const ContactGraph& graph) {
  if (graph.body_count() == 2 && graph.interfaces().size() == 1) return;
  throw InputError("coupling.algorithm \"" + to_string(options.algorithm) +
                   "\" couples exactly two bodies with one contact interface; this run has " +
                   std::to_string(graph.body_count()) + " bodies and " +
                   std::to_string(graph.interfaces().size()) +
                   " contact interfaces: use \"robin\" or \"robin-constant\"");
}

/// The bodies whose supports leave rigid motions free (body order).
std::vector<int> floating_bodies(const CouplingProblem& problem) {
  std::vector<int> floating;
  for (std::size_t body = 0; body < problem.rigid_modes.size(); ++body) {
    if (problem.rigid_modes[body] > 0) floating.push_back(static_cast<int>(body));
  }
  return floating;
}

/// The colouring of "robin" with floating bodies: two_colouring() with every connected component
/// that holds floating bodies coloured so that they lie in class 0. Throws InputError when that
/// is impossible (an odd cycle, or floating bodies in both classes of a component) or when
/// stopping "joint" is asked for (class 1 is frozen, so the joint state is not a solution).
std::vector<int> floating_colouring(const CouplingProblem& problem, const CouplingOptions& options,
                                    const std::vector<int>& floating) {
  const std::string named = "the floating " + describe_bodies(floating);
  const std::optional<std::vector<int>> colouring = problem.graph.two_colouring();
  if (!colouring) {
    throw InputError("coupling.algorithm \"robin\": " + named +
                     " lie in a contact graph with an odd cycle, which has no obstacle sequence "
                     "that avoids their Neumann response; use \"robin-constant\"");
  }
  std::vector<int> colours = *colouring;
  const std::vector<int> component = problem.graph.components();
  for (const int body : floating) {
    const int flip = colours[static_cast<std::size_t>(body)];
    std::vector<int> members;
    for (std::size_t other = 0; other < colours.size(); ++other) {
      if (component[other] != component[static_cast<std::size_t>(body)]) continue;
      colours[other] ^= flip;  // the body's class becomes 0
      members.push_back(static_cast<int>(other));
    }
    for (const int other : floating) {
      if (component[static_cast<std::size_t>(other)] == component[static_cast<std::size_t>(body)] &&
          colours[static_cast<std::size_t>(other)] != 0) {
        throw InputError("coupling.algorithm \"robin\": the floating " +
                         describe_bodies({body, other}) +
                         " touch through an odd number of interfaces (they lie in both colour "
                         "classes), so each obstacle sequence needs a floating body's Neumann "
                         "response; use \"robin-constant\"");
      }
    }
  }
  if (options.stopping == StoppingRule::joint) {
    throw InputError("coupling.stopping \"joint\" with " + named +
                     ": only the obstacle sequence of the floating bodies' colour class is "
                     "defined and the joint state never becomes a solution; use "
                     "\"either-sequence\"");
  }
  return colours;
}

/// The "robin" scheme: with floating bodies, their class 0 runs and class 1 is frozen.
std::unique_ptr<CouplingScheme> make_robin_scheme(const CouplingOptions& options,
                                                  const std::vector<SubdomainPort*>& ports,
                                                  const CouplingProblem& problem) {
  const std::vector<int> floating = floating_bodies(problem);
  if (floating.empty()) {
    return std::make_unique<RobinScheme>(ports, problem, 0.0, problem.graph.two_colouring(), -1);
  }
  return std::make_unique<RobinScheme>(ports, problem, 0.0,
                                       floating_colouring(problem, options, floating), 1);
}

/// "dirichlet-neumann": the contact body, which must be the floating one when there is one.
int dirichlet_neumann_contact_body(const CouplingOptions& options,
                                   const std::vector<SubdomainPort*>& ports,
                                   const CouplingProblem& problem) {
  const std::vector<int> floating = floating_bodies(problem);
  if (floating.size() == 2) {
    throw InputError(
        "coupling.algorithm \"dirichlet-neumann\": both bodies are floating "
        "bodies, and the Neumann body must not be (its Neumann solve needs a contact "
        "force that balances its loads); use \"robin\"");
  }
  // contact_body "1" and "2" are 1-based; the body indices here are 0-based.
  const int chosen = options.contact_body == ContactBodyChoice::first    ? 0
                     : options.contact_body == ContactBodyChoice::second ? 1
                     : floating.empty() ? more_compliant_body(ports, problem)
                                        : floating.front();
  if (!floating.empty() && chosen != floating.front()) {
    throw InputError("coupling.algorithm \"dirichlet-neumann\": body " +
                     std::to_string(floating.front() + 1) +
                     " is a floating body and must be the contact body (its Neumann solve needs "
                     "a contact force that balances its loads): set coupling.contact_body = \"" +
                     std::to_string(floating.front() + 1) + "\" or \"auto\"");
  }
  return chosen;
}

}  // namespace

std::vector<Eigen::VectorXd> CouplingState::normal_traces() const {
  std::vector<Eigen::VectorXd> values;
  for (const BodyInterfaceState& body : bodies) values.push_back(body.normal_trace);
  return values;
}

std::vector<Eigen::VectorXd> CouplingState::contact_forces() const {
  std::vector<Eigen::VectorXd> values;
  for (const BodyInterfaceState& body : bodies) values.push_back(body.contact_force);
  return values;
}

std::vector<Eigen::VectorXd> CouplingState::corrections() const {
  std::vector<Eigen::VectorXd> values;
  for (const BodyInterfaceState& body : bodies) values.push_back(body.correction);
  return values;
}

Eigen::VectorXd short_wavelength_forces(const ContactPairing& pairing) {
  const std::size_t size = pairing.size();
  Eigen::VectorXd forces = pairing.weights();
  if (size < 2) return forces;
  // Principal direction t of the pair positions; the pairs ranked by t . x alternate in sign.
  // Plane bodies rank in the plane (x, y), solid bodies in space.
  std::vector<std::size_t> order(size);
  std::iota(order.begin(), order.end(), 0);
  if (pairing.dimension == 3) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const ContactPair& pair : pairing.pairs) mean += pair.position / static_cast<double>(size);
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (const ContactPair& pair : pairing.pairs) {
      scatter += (pair.position - mean) * (pair.position - mean).transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    const Eigen::Vector3d direction = eigen.eigenvectors().col(2);  // largest eigenvalue
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return direction.dot(pairing.pairs[a].position) < direction.dot(pairing.pairs[b].position);
    });
  } else {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const ContactPair& pair : pairing.pairs) {
      mean += pair.position.head<2>() / static_cast<double>(size);
    }
    Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
    for (const ContactPair& pair : pairing.pairs) {
      scatter += (pair.position.head<2>() - mean) * (pair.position.head<2>() - mean).transpose();
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eigen(scatter);
    const Eigen::Vector2d direction = eigen.eigenvectors().col(1);  // largest eigenvalue
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
      return direction.dot(pairing.pairs[a].position.head<2>()) <
             direction.dot(pairing.pairs[b].position.head<2>());
    });
  }
  for (std::size_t rank = 1; rank < size; rank += 2) {
    forces[static_cast<Eigen::Index>(order[rank])] *= -1.0;
  }
  return forces;
}

CouplingProblem two_body_problem(const ContactPairing& pairing) {
  CouplingProblem problem;
  problem.graph = ContactGraph::two_bodies(static_cast<Eigen::Index>(pairing.size()));
  problem.gaps = pairing.gaps();
  problem.weights = pairing.weights();
  problem.probe_forces = short_wavelength_forces(pairing);
  return problem;
}

std::unique_ptr<CouplingScheme> make_coupling_scheme(const CouplingOptions& options,
                                                     const std::vector<SubdomainPort*>& ports,
                                                     const CouplingProblem& problem) {
  const ContactGraph& graph = problem.graph;
  if (static_cast<int>(ports.size()) != graph.body_count()) {
    throw InputError("the coupling has " + std::to_string(ports.size()) + " ports for " +
                     std::to_string(graph.body_count()) + " bodies");
  }
  if (!problem.rigid_modes.empty() &&
      static_cast<int>(problem.rigid_modes.size()) != graph.body_count()) {
    throw InputError("the coupling has rigid mode counts for " +
                     std::to_string(problem.rigid_modes.size()) + " of " +
                     std::to_string(graph.body_count()) + " bodies");
  }
  switch (options.algorithm) {
    case CouplingAlgorithm::robin:
      return make_robin_scheme(options, ports, problem);
    case CouplingAlgorithm::robin_constant:
      if (!(options.alpha > 0.0)) {
        throw InputError("coupling.alpha must be > 0 for the algorithm \"robin-constant\"");
      }
      if (problem.weights.size() != problem.gaps.size() || (problem.weights.array() <= 0.0).any()) {
        throw InputError(
            "the algorithm \"robin-constant\" needs a positive boundary weight per pair");
      }
      return std::make_unique<RobinScheme>(ports, problem, options.alpha,
                                           problem.graph.two_colouring(), -1);
    case CouplingAlgorithm::dirichlet_neumann: {
      require_two_bodies(options, graph);
      const int contact_body = dirichlet_neumann_contact_body(options, ports, problem);
      return std::make_unique<DirichletNeumannScheme>(ports, problem.gaps, contact_body);
    }
    case CouplingAlgorithm::neumann_neumann:
      require_two_bodies(options, graph);
      if (const std::vector<int> floating = floating_bodies(problem); !floating.empty()) {
        throw InputError(
            "coupling.algorithm \"neumann-neumann\" corrects both bodies by Neumann "
            "solves, which the floating " +
            describe_bodies(floating) +
            " does not have (its loads need not balance the force jump); use "
            "\"robin\" or \"dirichlet-neumann\" with the floating body as contact "
            "body");
      }
      return std::make_unique<NeumannNeumannScheme>(ports, problem.gaps);
  }
  throw std::logic_error("make_coupling_scheme: a coupling algorithm outside its enum");
}

}  // namespace robin
