#include "coupling/monolithic_solver.hpp"

#include <algorithm>
#include <chrono>
#include <limits>

#include <Eigen/SVD>

#include "numerics/errors.hpp"
#include "numerics/nonnegative_least_squares.hpp"
#include "numerics/smalbe.hpp"

namespace robin {
namespace {

/// sum_alpha C_alpha' F^alpha C_alpha x: the compliance of the graph's bodies seen by a common
/// contact force on every row.
class GraphComplianceOperator final : public LinearOperator {
 public:
  GraphComplianceOperator(const std::vector<const BodySolver*>& bodies, const ContactGraph& graph)
      : bodies_(bodies), graph_(graph) {}
  int size() const override { return static_cast<int>(graph_.total_rows()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    y = Eigen::VectorXd::Zero(x.size());
    for (std::size_t body = 0; body < bodies_.size(); ++body) {
      const int index = static_cast<int>(body);
      if (graph_.body_rows(index) == 0) continue;
      bodies_[body]->compliance().apply(graph_.body_part(index, x), scratch_);
      graph_.add_body_part(index, scratch_, y);
    }
  }

 private:
  const std::vector<const BodySolver*>& bodies_;
  const ContactGraph& graph_;
  mutable Eigen::VectorXd scratch_;
};

double maximum_absolute(const Eigen::VectorXd& values) {
  return values.size() == 0 ? 0.0 : values.lpNorm<Eigen::Infinity>();
}

/// The equality G lambda = h of the floating bodies, in global row order.
struct GraphEquality {
  Eigen::MatrixXd matrix;           // G: the rows (B^a R^a)' C_a of every floating body a
  Eigen::VectorXd target;           // h: the R^a'f^a
  std::vector<int> floating;        // the floating bodies, in body order
  std::vector<Eigen::Index> first;  // their first row in G
};

GraphEquality graph_equality(const std::vector<const BodySolver*>& bodies,
                             const ContactGraph& graph) {
  GraphEquality equality;
  std::vector<Eigen::VectorXd> rows, targets;
  Eigen::Index count = 0;
  for (std::size_t body = 0; body < bodies.size(); ++body) {
    const int modes = bodies[body]->rigid_mode_count();
    if (modes == 0) continue;
    equality.floating.push_back(static_cast<int>(body));
    equality.first.push_back(count);
    for (int mode = 0; mode < modes; ++mode) {
      Eigen::VectorXd row = Eigen::VectorXd::Zero(graph.total_rows());
      graph.add_body_part(static_cast<int>(body), bodies[body]->rigid_trace().col(mode), row);
      rows.push_back(row);
    }
    targets.push_back(bodies[body]->rigid_load());
    count += modes;
  }
  equality.matrix.resize(count, graph.total_rows());
  for (Eigen::Index row = 0; row < count; ++row) {
    equality.matrix.row(row) = rows[static_cast<std::size_t>(row)].transpose();
  }
  equality.target = concatenate(targets);
  return equality;
}

/// Throws SingularBodyError when G is rank-deficient or G lambda = h has no lambda >= 0.
void check_graph_equality(const GraphEquality& equality) {
  const std::string floating = "the floating " + describe_bodies(equality.floating);
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(equality.matrix);
  const Eigen::VectorXd& singular = svd.singularValues();
  if (equality.matrix.cols() < equality.matrix.rows() ||
      !(singular[singular.size() - 1] > 1e-8 * singular[0])) {
    throw SingularBodyError(floating +
                            " have a free sliding direction: a rigid motion of them "
                            "together moves none of the contact rows (e.g. floating bodies that "
                            "touch only each other), so contact cannot hold them");
  }
  const NonnegativeLeastSquaresResult balance =
      solve_nonnegative_least_squares(equality.matrix, equality.target);
  if (balance.residual_norm > 1e-8 * equality.target.norm()) {
    throw SingularBodyError(floating +
                            ": the loads push them away from every contact: no "
                            "compressive contact forces balance their loads along their free "
                            "rigid motions");
  }
}

/// The dual with the floating bodies' equality rows, by SMALBE-M; the result as MPRGP's.
MprgpResult solve_with_equality(const LinearOperator& compliance,
                                const Eigen::VectorXd& right_hand_side,
                                const GraphEquality& equality, const Eigen::VectorXd& initial,
                                const MprgpParameters& parameters, Eigen::VectorXd& multiplier) {
  check_graph_equality(equality);
  SmalbeParameters smalbe;
  smalbe.relative_tolerance = parameters.relative_tolerance;
  smalbe.max_iterations = parameters.max_iterations;
  smalbe.operator_norm = parameters.operator_norm;
  const SmalbeResult result =
      solve_smalbe(compliance, right_hand_side, Eigen::VectorXd::Zero(initial.size()),
                   equality.matrix, equality.target, initial, Eigen::VectorXd(), smalbe);
  multiplier = result.multiplier;
  MprgpResult qp;
  qp.solution = result.solution;
  qp.gradient = result.gradient;
  qp.status = result.status;
  qp.iterations = result.iterations;
  qp.operator_applications = result.operator_applications;
  qp.projected_gradient_norm = result.projected_gradient_norm;
  qp.operator_norm = result.operator_norm;
  qp.message = result.message;
  return qp;
}

}  // namespace

InterfaceResiduals interface_residuals(const Eigen::VectorXd& gap, const Eigen::VectorXd& trace1,
                                       const Eigen::VectorXd& trace2, const Eigen::VectorXd& force1,
                                       const Eigen::VectorXd& force2, double displacement_floor) {
  constexpr double tiny = std::numeric_limits<double>::min();
  const double displacement_scale = std::max({maximum_absolute(gap), maximum_absolute(trace1),
                                              maximum_absolute(trace2), displacement_floor, tiny});
  const double force_scale = std::max({maximum_absolute(force1), maximum_absolute(force2), tiny});
  InterfaceResiduals residuals;
  for (Eigen::Index i = 0; i < gap.size(); ++i) {
    const double clearance = gap[i] - trace1[i] - trace2[i];
    const double force = 0.5 * (force1[i] + force2[i]);
    residuals.penetration = std::max(residuals.penetration, -clearance / displacement_scale);
    residuals.force_balance =
        std::max(residuals.force_balance, std::abs(force1[i] - force2[i]) / force_scale);
    residuals.complementarity =
        std::max(residuals.complementarity,
                 std::abs(force * clearance) / (force_scale * displacement_scale));
  }
  return residuals;
}

MonolithicResult solve_monolithic(const std::vector<const BodySolver*>& bodies,
                                  const ContactGraph& graph, const Eigen::VectorXd& gaps,
                                  const MprgpParameters& parameters,
                                  const Eigen::VectorXd& initial_force) {
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Index size = graph.total_rows();
  if (static_cast<int>(bodies.size()) != graph.body_count() || gaps.size() != size) {
    throw InputError("monolithic solve: " + std::to_string(bodies.size()) + " bodies and " +
                     std::to_string(gaps.size()) + " gaps for a contact graph of " +
                     std::to_string(graph.body_count()) + " bodies and " + std::to_string(size) +
                     " rows");
  }
  Eigen::VectorXd right_hand_side = Eigen::VectorXd::Zero(size);  // sum_alpha C_alpha' e^alpha
  for (std::size_t body = 0; body < bodies.size(); ++body) {
    const int index = static_cast<int>(body);
    if (bodies[body]->contact_size() != graph.body_rows(index)) {
      throw InputError("monolithic solve: body " + std::to_string(body + 1) +
                       " must be assigned its " + std::to_string(graph.body_rows(index)) +
                       " contact rows first");
    }
    if (graph.body_rows(index) > 0) {
      graph.add_body_part(index, bodies[body]->free_trace(), right_hand_side);
    }
  }
  right_hand_side -= gaps;
  const GraphComplianceOperator compliance(bodies, graph);
  MonolithicResult result;
  MprgpParameters scaled = parameters;
  scaled.solution_scaled_tolerance = true;  // resolve lambda relative to itself, not to |e - d|
  const Eigen::VectorXd initial = initial_force.size() == size
                                      ? Eigen::VectorXd(initial_force.cwiseMax(0.0))
                                      : Eigen::VectorXd(Eigen::VectorXd::Zero(size));
  const GraphEquality equality = graph_equality(bodies, graph);
  Eigen::VectorXd multiplier;
  result.qp =
      equality.floating.empty()
          ? solve_mprgp(compliance, right_hand_side, Eigen::VectorXd::Zero(size), initial, scaled)
          : solve_with_equality(compliance, right_hand_side, equality, initial, scaled, multiplier);
  result.contact_force = result.qp.solution;
  result.rigid_amplitudes.resize(bodies.size());
  for (std::size_t k = 0; k < equality.floating.size(); ++k) {
    const int body = equality.floating[k];
    result.rigid_amplitudes[static_cast<std::size_t>(body)] = -multiplier.segment(
        equality.first[k], bodies[static_cast<std::size_t>(body)]->rigid_mode_count());
  }
  // u_N = e - F lambda (+ B R alpha) on each body
  std::vector<Eigen::VectorXd> forces;
  for (std::size_t body = 0; body < bodies.size(); ++body) {
    const int index = static_cast<int>(body);
    Eigen::VectorXd product = Eigen::VectorXd::Zero(graph.body_rows(index));
    const Eigen::VectorXd force = graph.body_part(index, result.contact_force);
    if (force.size() > 0) bodies[body]->compliance().apply(force, product);
    Eigen::VectorXd trace = force.size() > 0 ? Eigen::VectorXd(bodies[body]->free_trace() - product)
                                             : Eigen::VectorXd();
    if (result.rigid_amplitudes[body].size() > 0) {
      trace += bodies[body]->rigid_trace() * result.rigid_amplitudes[body];
    }
    result.normal_traces.push_back(trace);
    forces.push_back(force);
  }
  result.residuals = interface_residuals(gaps, graph.side(0, result.normal_traces),
                                         graph.side(1, result.normal_traces), graph.side(0, forces),
                                         graph.side(1, forces));
  result.solve_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

MonolithicResult solve_monolithic(const BodySolver& body1, const BodySolver& body2,
                                  const ContactPairing& pairing, const MprgpParameters& parameters,
                                  const Eigen::VectorXd& initial_force) {
  const Eigen::Index size = static_cast<Eigen::Index>(pairing.size());
  if (body1.contact_size() != size || body2.contact_size() != size) {
    throw InputError("monolithic solve: both bodies must be assigned the " + std::to_string(size) +
                     " contact pairs first");
  }
  return solve_monolithic({&body1, &body2}, ContactGraph::two_bodies(size), pairing.gaps(),
                          parameters, initial_force);
}

std::vector<MonolithicStep> solve_monolithic_steps(const std::vector<BodySolver*>& bodies,
                                                   const ContactGraph& graph,
                                                   const Eigen::VectorXd& gaps,
                                                   const LoadingOptions& loading,
                                                   const MprgpParameters& parameters) {
  const std::vector<const BodySolver*> solvers(bodies.begin(), bodies.end());
  std::vector<MonolithicStep> steps;
  for (std::size_t k = 0; k < loading.factors.size(); ++k) {
    MonolithicStep step;
    step.step = static_cast<int>(k + 1);
    step.factor = loading.factors[k];
    for (BodySolver* body : bodies) body->set_load_factor(step.factor);
    const Eigen::VectorXd initial = loading.warm_start && !steps.empty()
                                        ? steps.back().result.contact_force
                                        : Eigen::VectorXd();
    step.result = solve_monolithic(solvers, graph, gaps, parameters, initial);
    const bool converged = step.result.qp.status == QpStatus::converged;
    steps.push_back(std::move(step));
    if (!converged) break;
  }
  return steps;
}

std::vector<MonolithicStep> solve_monolithic_steps(BodySolver& body1, BodySolver& body2,
                                                   const ContactPairing& pairing,
                                                   const LoadingOptions& loading,
                                                   const MprgpParameters& parameters) {
  return solve_monolithic_steps({&body1, &body2},
                                ContactGraph::two_bodies(static_cast<Eigen::Index>(pairing.size())),
                                pairing.gaps(), loading, parameters);
}

}  // namespace robin
