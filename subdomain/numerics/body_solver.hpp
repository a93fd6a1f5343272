#pragma once
// One body of the contact problem: assembled stiffness, Dirichlet reduction, a Cholesky
// factor computed once, and the operators of the dual (contact-force) formulation on the
// contact nodes assigned to it.
//
// With B the contact constraint operator assigned to the body (numerics/contact_operator.hpp;
// node-to-node: (B u)_i = u(node_i).n_i), K the stiffness on free dofs and f the reduced load:
//   e = B K^{-1} f + B u_p          free normal trace (no contact force)
//   F = B K^{-1} B'                 interface compliance (Neumann-to-Dirichlet map)
//   u_N = e - F lambda              normal trace under nodal contact forces lambda
// where lambda_j >= 0 is the compressive contact force of constraint j, K u = f - B' lambda.
//
// Local contact problem (paper (10)): minimise 1/2 u'Ku - f'u subject to B u <= g, solved
// in its dual form  minimise 1/2 lambda'F lambda - lambda'(e - g), lambda >= 0, by MPRGP.
// Correction problem (paper (11)-(12)): K w = B' r, returns w_N = B w = F r.
//
// Floating bodies (BodySolverOptions::rigid_motions = held_by_contact; docs/method.md, "Floating
// bodies"). When the Dirichlet conditions leave rigid motions free, K has the kernel R (free x k,
// orthonormal, dof_map.hpp) and K^+ is the generalized inverse of generalized_inverse.hpp. Then
//   e = B K^+ f + B u_p,  F = B K^+ B',  G = (B R)' (k x n_c),  h = R'f,
// and u = K^+ (f - B' lambda) + R alpha solves K u = f - B' lambda iff G lambda = h. The local
// contact problem's dual gains that equality:
//   minimise 1/2 lambda'F lambda - lambda'(e - g)  s.t.  lambda >= 0,  G lambda = h,
// solved by SMALBE-M (smalbe.hpp) with multiplier mu; alpha = -mu, and
//   u_N = e - F lambda + G' alpha = g - (F lambda - (e - g) + G'mu),
// g minus the gradient of the Lagrangian, as without rigid motions. Refused (SingularBodyError
// naming the body): B R rank-deficient, at assign_contact (a free sliding direction: a rigid motion
// that moves no contact row, which contact cannot hold), and an equality without a solution
// lambda >= 0 (nonnegative_least_squares.hpp), at assign_contact and every contact solve (the loads
// push the body away from every contact). The correction solve of a floating body returns
//   w_N = B K^dagger B' r,  K^dagger = P K^+ P,  P = I - R R'
// (the Moore-Penrose inverse): K w = B'r is solvable only when G r = 0, and then w is its solution
// orthogonal to R; otherwise the unbalanced rigid part R R'B'r of the load is removed first. The
// coupling uses the correction of a floating body only where it is well defined
// (coupling_scheme.hpp). Its Neumann solve, K u = f - B'lambda for a given lambda, is defined
// only for balanced lambda, which a Neumann body does not get: solve_neumann refuses it.
//
// Iterative inner solver (BodySolverOptions::linear_solver = multigrid; docs/method.md). K is
// not factorized: K x = b is solved by conjugate gradients preconditioned by smoothed-aggregation
// AMG (algebraic_multigrid.hpp), whose memory grows like the dofs, not like a 3D factor's fill.
// F is then never formed; the local contact problem is solved in its primal form by a primal-dual
// active set method with projected conjugate gradients (primal_contact.hpp), warm-started from
// the previous solve's displacement and active set; e, the correction w_N = B K^{-1} B' r and the
// Neumann solve are one conjugate gradient solve each, and compliance() applies F by one solve
// per product. The answers equal the direct solver's to the iterative tolerance. Floating bodies
// need the direct solver (InputError). The primal method needs linearly independent contact rows
// (B B' positive definite over the rows that read a free dof): node-to-node rows and the rows of a
// mortar interface's non-mortar side have them; the mortar side's rows, when the non-mortar side
// is finer, do not. Then assign_contact factorizes K after all and the body continues with the
// direct solver (linear_solver() says which one it uses).
//
// Load factor t (quasi-static load steps): every load of the body (body force, tractions,
// pressures) and every prescribed displacement is multiplied by t, so f(t) = t f, u_p(t) = t u_p
// and e(t) = t e, by linearity; K, its factor and F do not depend on t and are kept.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "numerics/body_definition.hpp"
#include "numerics/cholesky.hpp"
#include "numerics/contact_operator.hpp"
#include "numerics/dof_map.hpp"
#include "numerics/elasticity.hpp"
#include "numerics/generalized_inverse.hpp"
#include "numerics/interface_description.hpp"
#include "numerics/linear_operator.hpp"
#include "numerics/mprgp.hpp"
#include "numerics/setup_progress.hpp"
#include "numerics/solution_history.hpp"

namespace robin {

class MultigridStiffnessSolver;  // primal_contact.hpp
struct PrimalContactState;       // primal_contact.hpp

enum class InterfaceOperatorKind {
  automatic,  // dense when the contact size is at most dense_limit, otherwise factor
  dense,      // F assembled once by blocked multi-right-hand-side solves; products cost O(n_c^2)
  factor,     // F applied through the factor: one solve (two triangular solves) per product
};

/// What a body whose Dirichlet conditions leave a rigid motion free is.
enum class RigidMotions {
  refuse,           // an error at setup (SingularBodyError): a forgotten support
  held_by_contact,  // a floating body, held by its contact rows (see the file comment)
};

/// How the body's stiffness systems K x = b are solved.
enum class LinearSolverKind {
  direct,     // a sparse Cholesky factor (CHOLMOD), computed once; contact solved in its dual
  multigrid,  // conjugate gradients preconditioned by smoothed-aggregation AMG; memory O(dofs);
              // contact solved in its primal form by a primal-dual active set method
  automatic,  // by the body's size (resolve_linear_solver)
};

/// A solid body of more degrees of freedom than this is solved by the multigrid solver when the
/// choice is automatic: a direct factor of a solid grows like N^(4/3) in memory and N^2 in work,
/// the multigrid solver like N (docs/benchmarks.md has the measurements behind the limit).
inline constexpr long automatic_multigrid_dofs = 150000;

/// The solver `kind` stands for, for a body of `dimension` with `dofs` degrees of freedom (2 or
/// 3 per node, prescribed ones included) and rigid motions `rigid_motions`: automatic is
/// multigrid for a solid (3D) body of more than automatic_multigrid_dofs that is not floating,
/// direct otherwise; direct and multigrid stand for themselves.
LinearSolverKind resolve_linear_solver(LinearSolverKind kind, int dimension, long dofs,
                                       RigidMotions rigid_motions);
/// "direct", "multigrid" or "auto" (the case file's and the protocol's names).
std::string linear_solver_name(LinearSolverKind kind);

struct BodySolverOptions {
  RigidMotions rigid_motions = RigidMotions::refuse;
  InterfaceOperatorKind interface_operator = InterfaceOperatorKind::automatic;
  LinearSolverKind linear_solver = LinearSolverKind::automatic;
  /// The automatic choice's limit on contact nodes. A dense F costs 8 n_c^2 bytes, and with the
  /// contact dofs last a dense trailing block of (d n_c)^2 / 2 entries in L; a solid body whose
  /// contact face has n_c nodes has a factor of far more entries than both, and applying F
  /// through such a factor streams all of L for every product of the contact solver.
  int dense_limit = 8000;
  /// Eliminate the free dofs of the contact boundaries last in the Cholesky factor when F will
  /// be dense (dense_interface_operator for the number of contact nodes), so a dense F comes
  /// from the factor's trailing block in O(m^2 n_c) instead of n_c solves with the whole factor
  /// (see numerics/cholesky.hpp).
  bool contact_unknowns_last = true;
  /// Limits checked before the work starts (0 = none): the body's degrees of freedom (2 or 3 per
  /// node, before assembly) and the memory of its Cholesky factor (from the symbolic
  /// analysis, before the numerical factorization). ResourceLimitError otherwise.
  long maximum_dofs = 0;
  double maximum_factor_bytes = 0.0;
  /// Told when each setup stage begins (assembly, ordering, factorization, interface
  /// operator); may be empty.
  SetupObserver observer;
};

struct ContactSolveResult {
  Eigen::VectorXd normal_trace;   // u_N (length)
  Eigen::VectorXd contact_force;  // lambda >= 0 (force; nodal, compression positive)
  std::vector<bool> active;       // lambda_i > 0
  QpStatus status = QpStatus::not_converged;
  int iterations = 0;
  int operator_applications = 0;
  double projected_gradient_norm = 0.0;
  double penetration = 0.0;      // max_i max(0, u_N,i - g_i)  (length)
  double complementarity = 0.0;  // max_i |lambda_i (g_i - u_N,i)| (work)
  double seconds = 0.0;
  std::string message;
};

/// The result of a contact solve from its dual QP's result `qp` (MprgpResult, SmalbeResult) at
/// `obstacle` g: lambda = the solution, u_N = g - gradient (the gradient of the dual is g - u_N),
/// the active rows (lambda > 0), the largest penetration and |lambda (g - u_N)|.
template <typename QpResult>
ContactSolveResult contact_solve_result(const QpResult& qp, const Eigen::VectorXd& obstacle) {
  ContactSolveResult result;
  result.contact_force = qp.solution;
  result.normal_trace = obstacle - qp.gradient;
  result.status = qp.status;
  result.iterations = qp.iterations;
  result.operator_applications = qp.operator_applications;
  result.projected_gradient_norm = qp.projected_gradient_norm;
  result.message = qp.message;
  result.active.resize(static_cast<std::size_t>(obstacle.size()));
  for (Eigen::Index i = 0; i < obstacle.size(); ++i) {
    const double clearance = obstacle[i] - result.normal_trace[i];
    result.active[static_cast<std::size_t>(i)] = result.contact_force[i] > 0.0;
    result.penetration = std::max(result.penetration, -clearance);
    result.complementarity =
        std::max(result.complementarity, std::abs(result.contact_force[i] * clearance));
  }
  return result;
}

/// Wall time of the setup stages (numerics/setup_progress.hpp), in seconds. For a body set up
/// anew; after replace_loads(): assembly is the load vector's, ordering 0 and factorization the
/// solve K^{-1} f with the kept factor.
struct BodyTimings {
  double assembly_seconds = 0.0;       // DOF map, stiffness, loads, contact boundary weights
  double ordering_seconds = 0.0;       // fill-reducing ordering and symbolic analysis
  double factorization_seconds = 0.0;  // numerical factorization and K^{-1} f
  double interface_seconds = 0.0;      // building e and (when dense) F
  /// assembly + ordering + factorization: the body's setup.
  double setup_seconds() const {
    return assembly_seconds + ordering_seconds + factorization_seconds;
  }
};

class BodySolver {
 public:
  /// Assembles and factorizes. Throws InputError for an unknown boundary name and
  /// SingularBodyError when the Dirichlet conditions leave a rigid motion free and
  /// options.rigid_motions is refuse.
  explicit BodySolver(BodyDefinition definition, BodySolverOptions options = {});
  ~BodySolver();
  BodySolver(const BodySolver&) = delete;
  BodySolver& operator=(const BodySolver&) = delete;

  const std::string& name() const { return definition_.name; }
  const BodyDefinition& definition() const { return definition_; }
  const Mesh& mesh() const { return definition_.mesh; }
  const DofMap& dofs() const { return *dofs_; }
  int free_dof_count() const { return dofs_->free_count(); }
  const BodyTimings& timings() const { return timings_; }
  /// Entries of the Cholesky factor L (0 with the multigrid solver).
  long factor_nonzeros() const;
  /// Solves with K: triangular solve pairs of the factor, or conjugate gradient solves.
  long solve_count() const;
  /// Conjugate gradient iterations of the multigrid solver so far (0 with the direct solver).
  long inner_iterations() const;
  /// The solver in use: the option's, or direct after assign_contact fell back to it (the file
  /// comment).
  LinearSolverKind linear_solver() const;
  /// k, the number of rigid motions the Dirichlet conditions leave free (0: K is SPD).
  int rigid_mode_count() const;
  /// R (free x k, orthonormal columns).
  const Eigen::MatrixXd& rigid_modes() const;
  /// G' = B R (n_c x k), valid after assign_contact.
  const Eigen::MatrixXd& rigid_trace() const { return rigid_trace_; }
  /// h = R'f at the current load factor (k values).
  Eigen::VectorXd rigid_load() const;
  /// alpha of the last contact solve (k values; zero before the first).
  const Eigen::VectorXd& rigid_amplitudes() const { return rigid_amplitudes_; }

  /// The nodes of the contact boundaries with geometric normals and weights, and per contact
  /// boundary its segments and its own nodes (numerics/interface_description.hpp).
  InterfaceDescription contact_boundary() const;
  /// The nodes of all contact boundaries (mesh node indices, ascending, each once).
  std::vector<int> contact_nodes() const;

  /// Whether `definition` set up with `options` has this body's stiffness factor and contact
  /// boundary: the same mesh (node coordinates, element blocks, boundary groups: bit for bit),
  /// material, prescribed degrees of freedom (which ones, not their values), contact boundaries
  /// (the same names in the same order) and factor options. Its name, loads, prescribed values and
  /// tags may differ.
  bool has_same_stiffness(const BodyDefinition& definition, const BodySolverOptions& options) const;
  /// Takes the name, loads, prescribed values and tags of `definition`, for which
  /// has_same_stiffness() holds, and keeps the factor of K: f is assembled again and K^{-1} f
  /// is one solve. Load factor 1, warm start reset. An assigned B stays (e is recomputed), and
  /// assign_contact() with the same B keeps F. `options` replaces the observer.
  void replace_loads(BodyDefinition definition, const BodySolverOptions& options);

  /// Sets the contact constraint operator B and builds e and F (F is kept when B equals the
  /// assigned one, e.g. a later run of the same body). Resets the warm start.
  /// Throws InputError (check_contact_operator) when B is malformed or uses a node that is not
  /// on a contact boundary; for a floating body SingularBodyError when B R is rank-deficient or
  /// G lambda = h has no solution lambda >= 0 (the file comment).
  void assign_contact(const ContactOperator& contact);
  /// The number of constraints (rows of B).
  int contact_size() const { return contact_.row_count(); }
  const ContactOperator& contact_operator() const { return contact_; }

  /// e = B K^{-1} f + B u_p.
  const Eigen::VectorXd& free_trace() const { return free_trace_; }
  /// The compliance F as an operator (valid after assign_contact).
  const LinearOperator& compliance() const { return *compliance_; }

  /// Paper step 1: contact with obstacle g (B u <= g), warm-started from the previous result.
  ContactSolveResult solve_contact(const Eigen::VectorXd& obstacle,
                                   const MprgpParameters& parameters = {});
  /// Forget the warm start (next solve starts from lambda = 0).
  void reset_warm_start();

  /// Scales every load and every prescribed displacement of the body by `factor` (relative to
  /// the definition's values, not to the current factor): f = factor f_1, u_p = factor u_p1,
  /// e = factor e_1. Keeps the factor of K, B, F and the contact warm start (the previous
  /// contact forces are the initial guess of the next contact solve). Throws InputError for a
  /// factor that is not finite or whose magnitude exceeds maximum_load_factor.
  void set_load_factor(double factor);
  double load_factor() const { return load_factor_; }
  /// The largest magnitude set_load_factor accepts.
  static constexpr double maximum_load_factor = 1e6;

  /// Paper step 2: w_N = B K^{-1} B' r for an interface force vector r (force); for a floating
  /// body w_N = B K^dagger B' r (the file comment). With the multigrid solver conjugate gradients
  /// start from the projection onto the last corrections solved to full accuracy
  /// (solution_history.hpp), which keeps them. `relative_accuracy` in (0, 1) says w_N is
  /// needed only to that relative accuracy: the multigrid solver's conjugate gradients then
  /// stop at that relative residual (the direct solver is exact anyway); 0 asks for full
  /// accuracy. Throws InputError for a force of the wrong size or an accuracy outside [0, 1).
  Eigen::VectorXd solve_correction(const Eigen::VectorXd& interface_force,
                                   double relative_accuracy = 0.0) const;
  /// The Neumann solve of the Dirichlet-Neumann iteration: u_N = B K^{-1} (f - B' lambda)
  /// = e - F lambda for a nodal contact force lambda (compression positive). Same cost as a
  /// correction solve (one product with F). Throws SingularBodyError for a floating body.
  Eigen::VectorXd solve_neumann(const Eigen::VectorXd& contact_force) const;

  /// Full displacement (mesh.dimension per node, prescribed values included) under contact forces
  /// lambda: u_f = K^+ (t f - B' lambda) + R alpha, alpha the rigid amplitudes of the last contact
  /// solve (none without rigid motions). With the multigrid solver, for a lambda other than the
  /// last contact solve's lambda_u, conjugate gradients start from u + x_0, u that solve's
  /// displacement (K u = t f - B' lambda_u) and x_0 the start of the kept corrections for the
  /// force lambda_u - lambda (solution_history.hpp): for the other obstacle sequence's force
  /// lambda = lambda_u + r, r the last correction's force (the fields of a completed sequence,
  /// docs/method.md), the start is already the solution.
  Eigen::VectorXd displacement(const Eigen::VectorXd& contact_force) const;
  /// The same with given rigid amplitudes alpha (k values), e.g. the monolithic reference's.
  Eigen::VectorXd displacement(const Eigen::VectorXd& contact_force,
                               const Eigen::VectorXd& rigid_amplitudes) const;
  /// Reaction forces K u - f at prescribed dofs (zero at free dofs), full size.
  Eigen::VectorXd reactions(const Eigen::VectorXd& displacement) const;
  /// Total applied external force (body force + tractions), (F_x, F_y, F_z) (F_z = 0 in 2D).
  Eigen::Vector3d applied_force() const;
  /// Contact force field as nodal vectors, full size: -B' lambda (force acting on this body).
  Eigen::VectorXd contact_force_field(const Eigen::VectorXd& contact_force) const;
  /// Boundary weight of every mesh node on the contact boundaries (zero elsewhere): the integral
  /// of its shape function over the contact boundaries (length in 2D, area in 3D; summed over the
  /// boundaries).
  const Eigen::VectorXd& boundary_weights() const { return boundary_weights_; }

 private:
  void assemble();
  /// The multigrid hierarchy of K and K^{-1} f by conjugate gradients (linear_solver multigrid).
  void set_up_multigrid(SparseMatrix&& reduced_stiffness);
  /// x = K^{-1} b by the factor or by conjugate gradients from `initial` (zero when empty).
  Eigen::VectorXd solve_stiffness(const Eigen::VectorXd& right_hand_side,
                                  const Eigen::VectorXd& initial = {}) const;
  /// Factorizes K (from the multigrid solver's copy) and continues with the direct solver.
  void fall_back_to_direct_solver();
  /// The local contact problem in its primal form (linear_solver multigrid).
  ContactSolveResult solve_primal_contact(const Eigen::VectorXd& obstacle);
  /// u + x_0 of displacement()'s comment.
  Eigen::VectorXd displacement_guess(const Eigen::VectorXd& contact_force) const;
  /// Assembles K, keeps its prescribed part (DofMap::prescribed_part: the reduced load and the
  /// reactions read nothing else) and returns the lower triangle of K_ff, freeing K.
  SparseMatrix assemble_reduced_stiffness();
  /// options_.observer, with the freed heap memory given back to the system (malloc_trim)
  /// when the numerical factorization begins.
  SetupObserver factorization_observer() const;
  /// At least one contact boundary, each a boundary of the mesh, none named twice (InputError).
  void check_contact_boundaries() const;
  void report(SetupStage stage) const;
  void build_interface_operator();
  /// Whether F is assembled densely for `contact_count` contact rows (before the memory check
  /// of build_interface_operator): `dense`, or `automatic` with at most dense_limit rows.
  bool dense_interface_operator(long contact_count) const;
  /// e = B K^{-1} f + B u_p at load factor 1 and at the current one, for the assigned B.
  void update_free_trace();
  /// Free dofs of the contact boundaries' nodes, to be eliminated last (empty when disabled).
  std::vector<int> trailing_unknowns() const;
  /// The position of each free dof's node, for the ordering's geometric dissection.
  std::vector<Eigen::Vector3d> free_dof_points() const;
  Eigen::VectorXd apply_transpose_trace(const Eigen::VectorXd& contact_force) const;  // B' lambda
  /// Floating bodies: B R of full column rank and G lambda = h solvable with lambda >= 0.
  void check_held_by_contact() const;
  /// The local contact problem of a floating body (SMALBE).
  ContactSolveResult solve_floating_contact(const Eigen::VectorXd& obstacle,
                                            const MprgpParameters& parameters);

  BodyDefinition definition_;
  BodySolverOptions options_;
  BodyTimings timings_;
  std::unique_ptr<DofMap> dofs_;
  SparseMatrix prescribed_stiffness_;  // K's entries in a prescribed row or column
  Eigen::VectorXd full_load_;
  Eigen::VectorXd reduced_load_;
  std::unique_ptr<GeneralizedInverse> factor_;  // K^{-1}, or K^+ for a floating body (direct)
  std::unique_ptr<MultigridStiffnessSolver> multigrid_;  // K^{-1} by AMG-PCG (multigrid)
  std::unique_ptr<PrimalContactState> primal_state_;     // the last primal contact solve
  // the last corrections (multigrid), the starts of the next ones and of displacement()'s solves
  static constexpr int kept_corrections = 4;
  mutable SolutionHistory correction_history_{kept_corrections};
  Eigen::MatrixXd no_rigid_modes_;  // R = free x 0 (multigrid)
  Eigen::VectorXd free_solution_;   // K^{-1} f (free dofs) at load factor 1

  ContactOperator contact_;
  Eigen::VectorXd boundary_weights_;
  SparseMatrix trace_;                // B on free dofs (n_c x free)
  Eigen::VectorXd prescribed_trace_;  // B u_p at load factor 1
  Eigen::VectorXd free_trace_;
  std::unique_ptr<LinearOperator> compliance_;
  Eigen::VectorXd warm_start_;
  double load_factor_ = 1.0;
  Eigen::VectorXd unit_free_trace_;   // e at load factor 1
  Eigen::MatrixXd rigid_trace_;       // B R (n_c x k)
  Eigen::VectorXd rigid_amplitudes_;  // alpha of the last contact solve
  Eigen::VectorXd warm_multiplier_;   // mu of the last contact solve (SMALBE warm start)
};

}  // namespace robin
