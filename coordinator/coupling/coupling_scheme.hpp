#pragma once
// The coordinator's algorithm family. A scheme turns the iterate x of one outer iteration into
// the subdomain requests of that iteration and returns the fixed-point map H(x); the loop in
// robin_iteration.cpp accelerates x -> H(x) and decides when to stop. Notation (pair order):
// d the initial gaps, m the boundary weights, e^a = B^a K^a^-1 f^a, F^a = B^a K^a^-1 B^a'.
//
//   "robin"              paper (Q_m), the Steklov-Poincare choice. x = (g1, g2), both contact
//                        solves, both correction solves w1_N = F1 (lambda2 - lambda1),
//                        w2_N = F2 (lambda1 - lambda2);
//                        H = (w2_N - u2_N + d, w1_N - u1_N + d).
//                        On a contact graph (contact_graph.hpp): x = (g^1, ..., g^N) in body
//                        order; w^a_N = F^a (lambda^across - lambda^a) and
//                        H^a = (w_N - u_N)^across + d on each of body a's rows, "across" being
//                        the other side of the row.
//   "robin-constant"     paper (6) with a constant alpha_S (Remark 1): the correction w^b_N is
//                        replaced by alpha (lambda^a - lambda^b) / m (nodal forces turned into
//                        pressures); no correction solves.
//                        H = (alpha (lambda1 - lambda2)/m - u2_N + d,
//                             alpha (lambda2 - lambda1)/m - u1_N + d).
//   "dirichlet-neumann"  Bayada-Sabil-Sassi: x = g, the obstacle of the contact body D; D solves
//                        its contact problem (lambda), then the Neumann body N is loaded by
//                        lambda: u^N_N = e^N - F^N lambda; H = d - u^N_N. Sequential.
//   "neumann-neumann"    Bayada-Sabil-Sassi: x = g1, the gap is split, g2 = d - g1; both
//                        contact solves, then both Neumann corrections by the force jump
//                        j = lambda1 - lambda2: w^a_N = F^a j; H = g1 + (w1_N + w2_N) / 4
//                        (the classical quarter: exact in one step for identical bodies with
//                        delta = 1).
// Each fixed point solves the monolithic problem (docs/method.md). In the all-active regime
// the error of the robin blocks is multiplied by I - delta (I + F2 F1^-1) and
// I - delta (I + F1 F2^-1), that of dirichlet-neumann by I - delta (I + F^N (F^D)^-1).
//
// Completions ("robin" only): K2 u2 = f2 - B2' lambda1 has the trace u2_N - w2_N, so every
// iteration also yields two complete candidate states, one per obstacle sequence:
// (u1, lambda1; u2_N - w2_N, lambda1) and (u1_N - w1_N, lambda2; u2, lambda2). Either solves the
// monolithic KKT system when its penetration and complementarity vanish (docs/method.md,
// "Either sequence alone"); the loop may stop on the first that does. On a contact graph whose
// bodies can be 2-coloured (every row joins colours 0 and 1: a chain, a stack, an even ring),
// sequence c is colour class c: its bodies keep (u, lambda), every other body takes its
// neighbours' forces, lambda^across, with the trace u_N - w_N. A graph with an odd cycle has no
// completions (the loop stops on the joint state).
//
// Floating bodies (CouplingProblem::rigid_modes; body_solver.hpp, "Floating bodies"): a body
// whose supports leave k > 0 rigid motions has a contact solve (its dual carries the equality
// G lambda = h) but no Neumann response: K u = f - B' lambda^across is solvable only for a
// lambda^across that balances its loads, which nothing guarantees during the iteration (its
// correction solve returns the Moore-Penrose w_N = B K^dagger B' r, well defined but not the
// correction of the iteration). Obstacle sequence c reads the contact solves of class c and the
// Neumann responses (u - w)_N = e - F lambda^across of the other class, so it is well defined
// iff no floating body lies in the other class.
//   "robin": each connected component of the graph is coloured so that its floating bodies lie
//            in class 0 (refused, InputError naming the bodies, when they cannot: floating
//            bodies in both classes of a component, or any floating body in a graph with an odd
//            cycle). Sequence 1 (class 0) runs and is the only sequence; class 1's block is
//            frozen, H = x on it (its bodies' contact solves keep their initial obstacles; the
//            joint state is not a solution, so stopping "joint" is refused). The accepted state
//            is sequence 1's complete state, whose fixed point is the monolithic solution
//            (docs/method.md, "Floating bodies").
//   "robin-constant": uses only each body's own contact solve, defined for floating bodies;
//            runs unchanged (its fixed point: lambda^a = lambda^b and g^a = d - u^b_N).
//   "dirichlet-neumann": the floating body must be the contact body ("auto" chooses it); a
//            floating Neumann body, or two floating bodies, are refused.
//   "neumann-neumann": corrects both bodies by Neumann solves: refused with a floating body.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "coupling/case_file.hpp"
#include "coupling/contact_graph.hpp"
#include "coupling/contact_pairing.hpp"
#include "coupling/subdomain_port.hpp"

namespace robin {

/// One body's interface state, in its body order (contact_graph.hpp). Vectors a scheme does
/// not produce are zero (corrections of "robin-constant") or, for a body without an obstacle
/// (the Neumann body of "dirichlet-neumann"), the obstacle it implicitly sees, d - g.
struct BodyInterfaceState {
  Eigen::VectorXd obstacle;       // g in the contact solve
  Eigen::VectorXd normal_trace;   // u_N
  Eigen::VectorXd contact_force;  // lambda
  Eigen::VectorXd correction;     // w_N
};

/// The interface state of every body (for two bodies: body order = pair order).
struct CouplingState {
  std::vector<BodyInterfaceState> bodies;
  std::vector<Eigen::VectorXd> normal_traces() const;
  std::vector<Eigen::VectorXd> contact_forces() const;
  std::vector<Eigen::VectorXd> corrections() const;
};

/// What one outer iteration produced.
struct CouplingEvaluation {
  Eigen::VectorXd mapped;  // H(x)
  CouplingState state;
  /// Candidate complete states (see the header comment), empty for most schemes; element k
  /// belongs to obstacle sequence k (CouplingScheme::sequences).
  std::vector<CouplingState> completions;
  std::vector<int> active;         // per body: closed rows seen by its contact solve (0: none)
  std::vector<int> qp_iterations;  // per body: iterations of its contact QP (0: none)
  /// Critical path of the bodies' compute in this iteration (parallel requests count once).
  double critical_compute_seconds = 0.0;
};

/// An obstacle sequence: the bodies whose contact forces it follows and the blocks of the
/// iterate that are its obstacles (for "robin", a colour class of the contact graph).
struct ObstacleSequence {
  std::vector<int> bodies;
  std::vector<int> blocks;
};

class CouplingScheme {
 public:
  virtual ~CouplingScheme() = default;
  /// Sizes of the independent blocks of x (accelerated per block): for "robin" one block per
  /// obstacle sequence (two bodies: per body; a bipartite graph: per colour class, whose
  /// bodies' obstacles x stacks together), one block on a graph with an odd cycle.
  /// "robin-constant" has one block of all obstacles: its map couples them.
  virtual std::vector<int> block_sizes() const = 0;
  /// The obstacle sequences whose forces the loop follows (ForceSequence) and whose complete
  /// states evaluate() returns as completions (same order).
  virtual std::vector<ObstacleSequence> sequences() const = 0;
  /// True when both bodies carry the same contact force by construction ("dirichlet-neumann"):
  /// the loop then reports the force change between iterations as the force balance.
  virtual bool shares_contact_force() const { return false; }
  /// For logs and summary.json, e.g. "dirichlet-neumann (contact body 2, Neumann body 1)".
  virtual std::string describe() const = 0;
  /// x_0 from the user's initial obstacle g_0 (per row, global order).
  virtual Eigen::VectorXd initial_iterate(const Eigen::VectorXd& initial_obstacle) const = 0;
  /// The subdomain requests of one iteration at x. Throws PortError when a port fails or a
  /// contact QP does not converge.
  virtual CouplingEvaluation evaluate(const Eigen::VectorXd& iterate, int iteration) = 0;
  /// Only the contact solves of evaluate(iterate, iteration), results discarded: a server
  /// warm-starts its contact QP from its previous contact force, so a resumed iteration
  /// (iteration_checkpoint.hpp) first repeats the solves of the iterations it continues
  /// after. Throws PortError as evaluate does.
  virtual void repeat_contact_solves(const Eigen::VectorXd& iterate, int iteration) = 0;
};

/// Nodal forces r_i = +-m_i whose sign alternates from pair to pair along the contact zone
/// (pairs ranked along the principal direction of their positions): the shortest wavelength
/// the mesh carries.
Eigen::VectorXd short_wavelength_forces(const ContactPairing& pairing);

/// What a scheme needs to know about the constraints, in global row order (contact_graph.hpp).
struct CouplingProblem {
  ContactGraph graph = ContactGraph::two_bodies(0);
  Eigen::VectorXd gaps;     // d
  Eigen::VectorXd weights;  // m (needed by "robin-constant")
  /// A short-wavelength probe (for "dirichlet-neumann" with contact_body "auto").
  Eigen::VectorXd probe_forces;
  /// F^a r^a per body (body order, r^a body a's part of probe_forces) when the caller has
  /// measured them (the Robin loop does, for its residuals' scale); empty: a scheme that needs
  /// them solves them itself.
  std::vector<Eigen::VectorXd> probe_responses;
  /// k per body (body order): the rigid motions its supports leave free
  /// (InterfaceDescription::rigid_modes, filled by the caller from the ports' setup); empty: no
  /// floating bodies.
  std::vector<int> rigid_modes;
};

/// The problem of two bodies and one interface: the pairing's gaps, weights and
/// short-wavelength probe (body order = pair order).
CouplingProblem two_body_problem(const ContactPairing& pairing);

/// The scheme of options.algorithm on ports (one per body of problem.graph, in body order)
/// whose contact has been assigned (body alpha: its rows in body order). "dirichlet-neumann"
/// with contact_body "auto": the body with the larger r'F^a r, one correction solve each, takes
/// the obstacle; its sequence is the well-conditioned one, the error being multiplied by
/// I - delta (I + F^N (F^D)^-1). Short wavelengths decide, as the few smooth modes, such as a
/// cantilever's bending, are absorbed by the accelerator.
/// Throws InputError for an unknown algorithm, a missing alpha, an algorithm that couples
/// exactly two bodies ("dirichlet-neumann", "neumann-neumann") on another graph, or floating
/// bodies where the algorithm would need their Neumann response (the header comment).
std::unique_ptr<CouplingScheme> make_coupling_scheme(const CouplingOptions& options,
                                                     const std::vector<SubdomainPort*>& ports,
                                                     const CouplingProblem& problem);

}  // namespace robin
