#include "numerics/body_solver.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <functional>
#include <set>
#include <sstream>

#include "numerics/algebraic_multigrid.hpp"
#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"
#include "numerics/heap_memory.hpp"
#include "numerics/primal_contact.hpp"

namespace robin {
namespace {

/// The factor as text for messages ("nan", "inf", "2e+07").
std::string format_load_factor(double factor) {
  std::ostringstream text;
  text << factor;
  return text.str();
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// F = B K^{-1} B' applied through solves with K: one solve (two triangular solves of the
/// factor, or one conjugate gradient solve) per product.
class SolveComplianceOperator final : public LinearOperator {
 public:
  using StiffnessSolve = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;
  SolveComplianceOperator(const SparseMatrix& trace, StiffnessSolve solve)
      : trace_(trace), trace_transpose_(trace.transpose()), solve_(std::move(solve)) {}
  int size() const override { return static_cast<int>(trace_.rows()); }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    // y = B K^{-1} (B' x)
    y.noalias() = trace_ * solve_(Eigen::VectorXd(trace_transpose_ * x));
  }

 private:
  const SparseMatrix& trace_;
  SparseMatrix trace_transpose_;
  StiffnessSolve solve_;
};

/// F assembled column block by column block: F(:, J) = B K^{-1} B'(:, J).
Eigen::MatrixXd assemble_dense_compliance(const SparseMatrix& trace,
                                          const GeneralizedInverse& factor) {
  const Eigen::Index contact_count = trace.rows();
  const SparseMatrix trace_transpose = trace.transpose();
  Eigen::MatrixXd compliance(contact_count, contact_count);
  constexpr Eigen::Index block_width = 64;
  for (Eigen::Index first = 0; first < contact_count; first += block_width) {
    const Eigen::Index width = std::min(block_width, contact_count - first);
    const Eigen::MatrixXd loads = Eigen::MatrixXd(trace_transpose.middleCols(first, width));
    compliance.middleCols(first, width).noalias() = trace * factor.solve(loads);
  }
  // Symmetrise away the rounding of the solves: F is symmetric by construction.
  const Eigen::MatrixXd symmetric = 0.5 * (compliance + compliance.transpose());
  return symmetric;
}

/// Whether the rows of B (`trace`) that read a free dof are linearly independent: B B' over them
/// is positive definite (CholeskyFactor's pivot test), and then so is every subset of them.
bool independent_rows(const SparseMatrix& trace, const std::string& body_name) {
  const Eigen::VectorXd row_sizes = trace.cwiseAbs() * Eigen::VectorXd::Ones(trace.cols());
  std::vector<Eigen::Triplet<double>> selection;
  for (Eigen::Index row = 0; row < trace.rows(); ++row) {
    if (row_sizes[row] > 0.0) {
      selection.emplace_back(static_cast<int>(selection.size()), static_cast<int>(row), 1.0);
    }
  }
  if (selection.empty()) return true;
  SparseMatrix select(static_cast<Eigen::Index>(selection.size()), trace.rows());
  select.setFromTriplets(selection.begin(), selection.end());
  const SparseMatrix rows = select * trace;
  try {
    const CholeskyFactor factor(SparseMatrix(rows * rows.transpose()), body_name);
    return true;
  } catch (const SingularBodyError&) {
    return false;
  }
}

/// Prescribed value of every dof from the Dirichlet conditions. Two conditions that give the
/// same dof different values are an error.
std::vector<std::optional<double>> prescribed_dofs(const BodyDefinition& body) {
  const int dimension = body.mesh.dimension;
  std::vector<std::optional<double>> prescribed(static_cast<std::size_t>(body.mesh.dof_count()));
  std::vector<std::string> source(prescribed.size());
  auto prescribe = [&](int dof, double value, const std::string& boundary) {
    if (prescribed[dof] && std::abs(*prescribed[dof] - value) > 1e-14 * (1 + std::abs(value))) {
      static const char* const component_names[] = {" (u_x)", " (u_y)", " (u_z)"};
      throw InputError("body '" + body.name + "': Dirichlet conditions on '" + source[dof] +
                       "' and '" + boundary + "' prescribe different values to node tag " +
                       std::to_string(body.mesh.node_tags[dof / dimension]) +
                       component_names[dof % dimension]);
    }
    prescribed[dof] = value;
    source[dof] = boundary;
  };
  for (const DirichletCondition& condition : body.dirichlet) {
    if (condition.z && dimension == 2) {
      throw InputError("body '" + body.name + "': the Dirichlet condition on '" +
                       condition.boundary + "' prescribes u_z, but the body is two-dimensional");
    }
    const std::optional<double> values[] = {condition.x, condition.y, condition.z};
    for (int node : body.mesh.boundary(condition.boundary).nodes()) {
      for (int component = 0; component < dimension; ++component) {
        if (values[component]) {
          prescribe(dimension * node + component, *values[component], condition.boundary);
        }
      }
    }
  }
  return prescribed;
}

Eigen::VectorXd assemble_external_load(const BodyDefinition& body) {
  const Mesh& mesh = body.mesh;
  const Eigen::Vector3d body_force = body.body_force;
  Eigen::VectorXd load = Eigen::VectorXd::Zero(mesh.dof_count());
  if (body_force.squaredNorm() > 0) {
    load += assemble_body_force(mesh, [body_force](const Eigen::Vector3d&) { return body_force; });
  }
  for (const TractionCondition& traction : body.tractions) {
    const BoundaryGroup& group = mesh.boundary(traction.boundary);
    if (traction.is_pressure) {
      const double pressure = traction.pressure;
      load += assemble_boundary_traction(
          mesh, group, [pressure](const Eigen::Vector3d&, const Eigen::Vector3d& normal) {
            return Eigen::Vector3d(-pressure * normal);  // compression positive
          });
    } else {
      const Eigen::Vector3d vector = traction.vector;
      load += assemble_boundary_traction(
          mesh, group, [vector](const Eigen::Vector3d&, const Eigen::Vector3d&) { return vector; });
    }
  }
  return load;
}

/// The reference coordinates of the centre of a facet of `type`.
Eigen::Vector3d group_facet_centre(FacetType type) {
  if (facet_dimension(type) == 1) return Eigen::Vector3d::Zero();
  return reference_centroid(face_parametrization(type));
}

/// Reverses the orientation of the facet whose nodes start at `nodes` (Gmsh order): an edge's
/// endpoints swap; a face's corners run the other way round (0, 2, 1 / 0, 3, 2, 1), with a
/// triangle6's midside nodes following their edges (3, 4, 5 -> 5, 4, 3).
void reverse_facet(FacetType type, int* nodes) {
  switch (type) {
    case FacetType::line2:
    case FacetType::line3:
      std::swap(nodes[0], nodes[1]);
      return;
    case FacetType::triangle3:
      std::swap(nodes[1], nodes[2]);
      return;
    case FacetType::triangle6:
      std::swap(nodes[1], nodes[2]);
      std::swap(nodes[3], nodes[5]);
      return;
    case FacetType::quadrilateral4:
      std::swap(nodes[1], nodes[3]);
      return;
  }
}

/// The facets of `group` as positions into `nodes` (sorted), each oriented outward (an edge with
/// the body on its left, a face with its right-hand normal out of the body).
std::vector<int> oriented_facets(const Mesh& mesh, const BoundaryGroup& group,
                                 const std::vector<int>& nodes) {
  const NodeElementMap adjacency(mesh, group);
  const int count = nodes_per_facet(group.type);
  const Eigen::Vector3d centre = group_facet_centre(group.type);
  std::vector<int> facets;
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    // Without adjacency the normal is the facet's own orientation.
    const Eigen::Vector3d own = FacetGeometry(mesh, group, e).evaluate(centre).outward_normal;
    const Eigen::Vector3d outward =
        FacetGeometry(mesh, group, e, adjacency).evaluate(centre).outward_normal;
    const std::size_t first = facets.size();
    for (int i = 0; i < count; ++i) {
      const int node = group.connectivity[e * count + i];
      facets.push_back(
          static_cast<int>(std::lower_bound(nodes.begin(), nodes.end(), node) - nodes.begin()));
    }
    if (own.dot(outward) < 0.0) reverse_facet(group.type, &facets[first]);
  }
  return facets;
}

/// Whether two meshes have the same nodes, elements and boundary groups (bit for bit).
bool same_geometry(const Mesh& left, const Mesh& right) {
  if (left.nodes != right.nodes || left.blocks.size() != right.blocks.size() ||
      left.boundaries.size() != right.boundaries.size()) {
    return false;
  }
  for (std::size_t b = 0; b < left.blocks.size(); ++b) {
    if (left.blocks[b].type != right.blocks[b].type ||
        left.blocks[b].connectivity != right.blocks[b].connectivity) {
      return false;
    }
  }
  return std::equal(left.boundaries.begin(), left.boundaries.end(), right.boundaries.begin(),
                    [](const auto& one, const auto& other) {
                      return one.first == other.first && one.second.type == other.second.type &&
                             one.second.connectivity == other.second.connectivity;
                    });
}

bool same_material(const Material& left, const Material& right) {
  return left.stiffness == right.stiffness && left.model == right.model &&
         left.out_of_plane_poisson == right.out_of_plane_poisson;
}

/// Whether the same degrees of freedom are prescribed (whatever their values).
bool same_prescribed_set(const std::vector<std::optional<double>>& prescribed, const DofMap& dofs) {
  if (static_cast<int>(prescribed.size()) != dofs.total_count()) return false;
  for (std::size_t dof = 0; dof < prescribed.size(); ++dof) {
    if (prescribed[dof].has_value() != dofs.is_prescribed(static_cast<int>(dof))) return false;
  }
  return true;
}

bool same_factor_options(const BodySolverOptions& left, const BodySolverOptions& right) {
  return left.interface_operator == right.interface_operator &&
         left.linear_solver == right.linear_solver && left.dense_limit == right.dense_limit &&
         left.contact_unknowns_last == right.contact_unknowns_last &&
         left.maximum_dofs == right.maximum_dofs &&
         left.maximum_factor_bytes == right.maximum_factor_bytes &&
         left.rigid_motions == right.rigid_motions;
}

}  // namespace

LinearSolverKind resolve_linear_solver(LinearSolverKind kind, int dimension, long dofs,
                                       RigidMotions rigid_motions) {
  if (kind != LinearSolverKind::automatic) return kind;
  return dimension == 3 && dofs > automatic_multigrid_dofs && rigid_motions == RigidMotions::refuse
             ? LinearSolverKind::multigrid
             : LinearSolverKind::direct;
}

std::string linear_solver_name(LinearSolverKind kind) {
  switch (kind) {
    case LinearSolverKind::multigrid:
      return "multigrid";
    case LinearSolverKind::automatic:
      return "auto";
    case LinearSolverKind::direct:
      break;
  }
  return "direct";
}

BodySolver::BodySolver(BodyDefinition definition, BodySolverOptions options)
    : definition_(std::move(definition)), options_(options) {
  options_.linear_solver = resolve_linear_solver(options_.linear_solver, definition_.mesh.dimension,
                                                 static_cast<long>(definition_.mesh.dof_count()),
                                                 options_.rigid_motions);
  assemble();
}

BodySolver::~BodySolver() = default;

void BodySolver::report(SetupStage stage) const {
  if (options_.observer) options_.observer(stage);
}

void BodySolver::assemble() {
  auto start = std::chrono::steady_clock::now();
  const Mesh& mesh = definition_.mesh;
  if (mesh.node_count() == 0 || mesh.element_count() == 0) {
    throw InputError("body '" + name() + "': the mesh has no elements");
  }
  check_contact_boundaries();
  const long dof_count = long{mesh.dimension} * static_cast<long>(mesh.node_count());
  if (options_.maximum_dofs > 0 && dof_count > options_.maximum_dofs) {
    throw ResourceLimitError("body '" + name() + "': " + std::to_string(dof_count) +
                             " degrees of freedom, above this server's limit of " +
                             std::to_string(options_.maximum_dofs) +
                             " (robin-subdomain --max-dofs raises it)");
  }
  report(SetupStage::assembly);
  dofs_ = std::make_unique<DofMap>(prescribed_dofs(definition_));
  if (options_.rigid_motions == RigidMotions::refuse && !removes_rigid_motions(mesh, *dofs_)) {
    throw SingularBodyError(
        "body '" + name() +
        "': the Dirichlet conditions leave a rigid motion free (translation or rotation); "
        "fix u_x and u_y on a boundary segment, or enough components on several boundaries");
  }
  SparseMatrix reduced_stiffness = assemble_reduced_stiffness();
  full_load_ = assemble_external_load(definition_);
  reduced_load_ = dofs_->reduce_load(prescribed_stiffness_, full_load_);
  for (std::size_t k = 0; k < definition_.contact_boundaries.size(); ++k) {
    const Eigen::VectorXd weights =
        robin::boundary_weights(mesh, mesh.boundary(definition_.contact_boundaries[k]));
    if (k == 0) {
      boundary_weights_ = weights;
    } else {
      boundary_weights_ += weights;
    }
  }
  timings_.assembly_seconds = seconds_since(start);

  start = std::chrono::steady_clock::now();
  if (options_.linear_solver == LinearSolverKind::multigrid) {
    set_up_multigrid(std::move(reduced_stiffness));
    timings_.factorization_seconds = seconds_since(start);
    return;
  }
  report(SetupStage::ordering);
  Eigen::MatrixXd kernel = options_.rigid_motions == RigidMotions::refuse
                               ? Eigen::MatrixXd(dofs_->free_count(), 0)
                               : rigid_body_modes(mesh, *dofs_);
  factor_ = std::make_unique<GeneralizedInverse>(
      std::move(reduced_stiffness), std::move(kernel), name(),
      FactorizationOptions{trailing_unknowns(), options_.maximum_factor_bytes,
                           factorization_observer(), free_dof_points()});
  free_solution_ = factor_->solve(reduced_load_);  // K^{-1} f
  rigid_amplitudes_ = Eigen::VectorXd::Zero(rigid_mode_count());
  // the ordering as the factor measured it; the rest (numerical factorization, K^{-1} f) here
  timings_.ordering_seconds = factor_->ordering_seconds();
  timings_.factorization_seconds = seconds_since(start) - timings_.ordering_seconds;
}

void BodySolver::set_up_multigrid(SparseMatrix&& reduced_stiffness) {
  if (options_.rigid_motions != RigidMotions::refuse &&
      !removes_rigid_motions(definition_.mesh, *dofs_)) {
    throw InputError("body '" + name() +
                     "': a floating body (rigid motions held by contact) needs the direct linear "
                     "solver; linear_solver = \"multigrid\" solves only bodies whose supports "
                     "hold them");
  }
  report(SetupStage::factorization);
  release_free_heap_memory();
  multigrid_ = std::make_unique<MultigridStiffnessSolver>(
      std::move(reduced_stiffness), free_rigid_body_modes(definition_.mesh, *dofs_),
      free_dof_nodes(definition_.mesh, *dofs_), definition_.mesh.nodes,
      PrimalContactOptions{}.relative_tolerance, name());  // K moved into the AMG
  free_solution_ = solve_stiffness(reduced_load_);         // K^{-1} f
  rigid_amplitudes_ = Eigen::VectorXd::Zero(0);
  no_rigid_modes_.resize(dofs_->free_count(), 0);
}

Eigen::VectorXd BodySolver::solve_stiffness(const Eigen::VectorXd& right_hand_side,
                                            const Eigen::VectorXd& initial) const {
  if (multigrid_) return multigrid_->solve(right_hand_side, initial);
  return factor_->solve(right_hand_side);
}

long BodySolver::factor_nonzeros() const {
  return factor_ ? factor_->factor_nonzeros() : 0;
}

long BodySolver::solve_count() const {
  return factor_ ? factor_->solve_count() : multigrid_->solve_count();
}

LinearSolverKind BodySolver::linear_solver() const {
  return multigrid_ ? LinearSolverKind::multigrid : LinearSolverKind::direct;
}

void BodySolver::fall_back_to_direct_solver() {
  SparseMatrix lower = multigrid_->stiffness_matrix();
  multigrid_.reset();
  factor_ = std::make_unique<GeneralizedInverse>(
      std::move(lower), Eigen::MatrixXd(dofs_->free_count(), 0), name(),
      FactorizationOptions{
          {}, options_.maximum_factor_bytes, factorization_observer(), free_dof_points()});
  free_solution_ = factor_->solve(reduced_load_);  // K^{-1} f
}

long BodySolver::inner_iterations() const {
  return multigrid_ ? multigrid_->iterations() : 0;
}

int BodySolver::rigid_mode_count() const {
  return factor_ ? factor_->rigid_mode_count() : 0;
}

const Eigen::MatrixXd& BodySolver::rigid_modes() const {
  return factor_ ? factor_->kernel() : no_rigid_modes_;
}

SparseMatrix BodySolver::assemble_reduced_stiffness() {
  const SparseMatrix stiffness = assemble_stiffness(definition_.mesh, definition_.material);
  prescribed_stiffness_ = dofs_->prescribed_part(stiffness);
  return dofs_->reduce_matrix_lower(stiffness);
}

SetupObserver BodySolver::factorization_observer() const {
  return [observer = options_.observer](SetupStage stage) {
    if (stage == SetupStage::factorization) release_free_heap_memory();
    if (observer) observer(stage);
  };
}

std::vector<Eigen::Vector3d> BodySolver::free_dof_points() const {
  std::vector<Eigen::Vector3d> points;
  points.reserve(static_cast<std::size_t>(dofs_->free_count()));
  for (const int node : free_dof_nodes(definition_.mesh, *dofs_)) {
    points.push_back(definition_.mesh.nodes[static_cast<std::size_t>(node)]);
  }
  return points;
}

std::vector<int> BodySolver::trailing_unknowns() const {
  std::vector<int> unknowns;
  const std::vector<int> nodes = contact_nodes();
  // the contact rows are not known before AssignContact: the contact nodes stand for them
  if (!options_.contact_unknowns_last || !dense_interface_operator(static_cast<long>(nodes.size())))
    return unknowns;
  for (int node : nodes) {
    const int dimension = definition_.mesh.dimension;
    for (int dof = dimension * node; dof < dimension * (node + 1); ++dof) {
      if (!dofs_->is_prescribed(dof)) unknowns.push_back(dofs_->free_index(dof));
    }
  }
  return unknowns;
}

void BodySolver::check_contact_boundaries() const {
  const std::vector<std::string>& names = definition_.contact_boundaries;
  if (names.empty()) throw InputError("body '" + name() + "': no contact boundary is named");
  for (std::size_t k = 0; k < names.size(); ++k) {
    definition_.mesh.boundary(names[k]);  // throws InputError for an unknown name
    if (std::find(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(k), names[k]) !=
        names.begin() + static_cast<std::ptrdiff_t>(k)) {
      throw InputError("body '" + name() + "': contact boundary '" + names[k] + "' is named twice");
    }
  }
}

std::vector<int> BodySolver::contact_nodes() const {
  const std::vector<std::string>& names = definition_.contact_boundaries;
  if (names.size() == 1) return definition_.mesh.boundary(names.front()).nodes();
  std::vector<int> nodes;
  for (const std::string& boundary : names) {
    const std::vector<int> group_nodes = definition_.mesh.boundary(boundary).nodes();
    nodes.insert(nodes.end(), group_nodes.begin(), group_nodes.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

InterfaceDescription BodySolver::contact_boundary() const {
  const Mesh& mesh = definition_.mesh;
  InterfaceDescription interface;
  interface.dimension = mesh.dimension;
  interface.dof_count = dofs_->free_count();
  interface.rigid_modes = rigid_mode_count();
  interface.node_ids = contact_nodes();
  const Eigen::VectorXd& weights = boundary_weights_;
  for (int node : interface.node_ids) {
    interface.node_tags.push_back(mesh.node_tags[node]);
    interface.coordinates.push_back(mesh.nodes[node]);
    interface.weights.push_back(weights[node]);
    std::array<bool, 3> fixed = {false, false, false};
    for (int component = 0; component < mesh.dimension; ++component) {
      fixed[component] = dofs_->is_prescribed(mesh.dimension * node + component);
    }
    interface.fixed.push_back(fixed);
  }
  // Per boundary its own normals and weights; the union's normal at a node is the normalized
  // sum of every boundary's measure-weighted normals there (numerics/interface_description.hpp).
  std::vector<Eigen::Vector3d> sums;
  for (const std::string& boundary : definition_.contact_boundaries) {
    const BoundaryGroup& group = mesh.boundary(boundary);
    ContactSurfaceDescription surface;
    surface.boundary = boundary;
    surface.facet_type = group.type;
    surface.facets = oriented_facets(mesh, group, interface.node_ids);
    const std::vector<int> nodes = group.nodes();
    const std::vector<Eigen::Vector3d> group_sums = boundary_normal_sums(mesh, group);
    surface.normals =
        unit_normals(mesh, group_sums, nodes, "boundary " + mesh.boundary_label(group));
    const Eigen::VectorXd group_weights = robin::boundary_weights(mesh, group);
    for (const int node : nodes) {
      surface.positions.push_back(static_cast<int>(
          std::lower_bound(interface.node_ids.begin(), interface.node_ids.end(), node) -
          interface.node_ids.begin()));
      surface.weights.push_back(group_weights[node]);
    }
    if (sums.empty()) {
      sums = group_sums;
    } else {
      for (std::size_t node = 0; node < sums.size(); ++node) sums[node] += group_sums[node];
    }
    interface.surfaces.push_back(std::move(surface));
  }
  if (interface.surfaces.size() == 1) {
    interface.normals = interface.surfaces.front().normals;
  } else {
    std::string names;
    for (const std::string& boundary : definition_.contact_boundaries) {
      names += (names.empty() ? "'" : ", '") + boundary + "'";
    }
    interface.normals = unit_normals(mesh, sums, interface.node_ids, "contact boundaries " + names);
  }
  return interface;
}

void BodySolver::assign_contact(const ContactOperator& contact) {
  const auto start = std::chrono::steady_clock::now();
  report(SetupStage::interface_operator);
  check_contact_operator(contact, contact_nodes(), definition_.mesh.dimension,
                         "body '" + name() + "'");
  const bool keep_compliance = compliance_ != nullptr && contact == contact_;
  if (!keep_compliance) {
    const int row_count = contact.row_count();
    const int dimension = definition_.mesh.dimension;
    std::vector<Eigen::Triplet<double>> triplets;
    for (int row = 0; row < row_count; ++row) {
      for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
        const int dof = dimension * contact.nodes[k] + contact.components[k];
        if (!dofs_->is_prescribed(dof)) {
          triplets.emplace_back(row, dofs_->free_index(dof), contact.values[k]);
        }
      }
    }
    contact_ = contact;
    trace_.resize(row_count, dofs_->free_count());
    trace_.setFromTriplets(triplets.begin(), triplets.end());
  }
  if (multigrid_ && !independent_rows(trace_, name())) fall_back_to_direct_solver();
  rigid_trace_ = trace_ * rigid_modes();  // B R
  update_free_trace();
  if (!keep_compliance) build_interface_operator();
  reset_warm_start();
  check_held_by_contact();
  timings_.interface_seconds = seconds_since(start);
}

void BodySolver::update_free_trace() {
  const ContactOperator& contact = contact_;
  const int dimension = definition_.mesh.dimension;
  prescribed_trace_ = Eigen::VectorXd::Zero(contact.row_count());
  for (int row = 0; row < contact.row_count(); ++row) {
    for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
      const int dof = dimension * contact.nodes[k] + contact.components[k];
      if (dofs_->is_prescribed(dof)) {
        prescribed_trace_[row] += contact.values[k] * dofs_->prescribed_values()[dof];
      }
    }
  }
  unit_free_trace_ = trace_ * free_solution_ + prescribed_trace_;  // e = B K^{-1} f + B u_p
  free_trace_ = load_factor_ * unit_free_trace_;
}

bool BodySolver::has_same_stiffness(const BodyDefinition& definition,
                                    const BodySolverOptions& options) const {
  BodySolverOptions resolved = options;  // "automatic" as the constructor resolves it
  resolved.linear_solver =
      resolve_linear_solver(options.linear_solver, definition.mesh.dimension,
                            static_cast<long>(definition.mesh.dof_count()), options.rigid_motions);
  if (definition.contact_boundaries != definition_.contact_boundaries ||
      !same_factor_options(resolved, options_) ||
      !same_material(definition.material, definition_.material) ||
      !same_geometry(definition.mesh, definition_.mesh)) {
    return false;
  }
  try {
    return same_prescribed_set(prescribed_dofs(definition), *dofs_);
  } catch (const InputError&) {
    return false;  // conflicting conditions: the full setup reports them
  }
}

void BodySolver::replace_loads(BodyDefinition definition, const BodySolverOptions& options) {
  auto start = std::chrono::steady_clock::now();
  options_.observer = options.observer;
  report(SetupStage::assembly);
  definition_ = std::move(definition);
  dofs_ = std::make_unique<DofMap>(prescribed_dofs(definition_));
  full_load_ = assemble_external_load(definition_);
  reduced_load_ = dofs_->reduce_load(prescribed_stiffness_, full_load_);
  timings_.assembly_seconds = seconds_since(start);
  start = std::chrono::steady_clock::now();
  free_solution_ = solve_stiffness(reduced_load_);  // K^{-1} f with the kept factor or AMG
  timings_.ordering_seconds = 0.0;
  timings_.factorization_seconds = seconds_since(start);
  load_factor_ = 1.0;
  if (compliance_) update_free_trace();
  reset_warm_start();
}

void BodySolver::build_interface_operator() {
  // A dense F takes 8 n_c^2 bytes: within the factor's memory limit, or F is applied through
  // the factor instead (same answers, more work per product).
  const double dense_bytes = 8.0 * contact_size() * static_cast<double>(contact_size());
  const bool dense_fits =
      options_.maximum_factor_bytes <= 0.0 || dense_bytes <= options_.maximum_factor_bytes;
  const bool dense = dense_fits && dense_interface_operator(contact_size());
  if (multigrid_) {
    // never dense: n_c conjugate gradient solves; the contact solve does not use F
    compliance_ = std::make_unique<SolveComplianceOperator>(
        trace_, [this](const Eigen::VectorXd& load) { return solve_stiffness(load); });
  } else if (dense && factor_->has_trailing_block()) {
    compliance_ = std::make_unique<DenseOperator>(factor_->trailing_congruence(trace_));
  } else if (dense) {
    compliance_ = std::make_unique<DenseOperator>(assemble_dense_compliance(trace_, *factor_));
  } else {
    compliance_ = std::make_unique<SolveComplianceOperator>(
        trace_, [this](const Eigen::VectorXd& load) { return factor_->solve(load); });
  }
}

bool BodySolver::dense_interface_operator(long contact_count) const {
  return options_.interface_operator == InterfaceOperatorKind::dense ||
         (options_.interface_operator == InterfaceOperatorKind::automatic &&
          contact_count <= options_.dense_limit);
}

void BodySolver::reset_warm_start() {
  warm_start_ = Eigen::VectorXd::Zero(contact_size());
  primal_state_ = std::make_unique<PrimalContactState>();
  correction_history_.clear();
  warm_multiplier_ = Eigen::VectorXd::Zero(rigid_mode_count());
  rigid_amplitudes_ = Eigen::VectorXd::Zero(rigid_mode_count());
}

void BodySolver::set_load_factor(double factor) {
  if (!std::isfinite(factor) || std::abs(factor) > maximum_load_factor) {
    throw InputError("body '" + name() + "': load factor " + format_load_factor(factor) +
                     " is not a finite number of magnitude at most 1e6");
  }
  if (factor != load_factor_ && primal_state_) {
    primal_state_->contact_force.resize(0);  // its u is no longer the solution at this factor
  }
  load_factor_ = factor;
  if (unit_free_trace_.size() > 0) free_trace_ = load_factor_ * unit_free_trace_;
}

ContactSolveResult BodySolver::solve_contact(const Eigen::VectorXd& obstacle,
                                             const MprgpParameters& parameters) {
  const auto start = std::chrono::steady_clock::now();
  if (obstacle.size() != contact_size()) {
    throw InputError("body '" + name() + "': obstacle has " + std::to_string(obstacle.size()) +
                     " values for " + std::to_string(contact_size()) + " contact nodes");
  }
  if (rigid_mode_count() > 0) return solve_floating_contact(obstacle, parameters);
  if (multigrid_) return solve_primal_contact(obstacle);
  // Dual problem: minimise 1/2 l'F l - l'(e - g), l >= 0. Its gradient F l - (e - g) equals
  // g - u_N, so u_N = g - gradient and the KKT conditions are the Signorini conditions.
  const Eigen::VectorXd right_hand_side = free_trace_ - obstacle;
  const Eigen::VectorXd lower = Eigen::VectorXd::Zero(contact_size());
  MprgpParameters scaled = parameters;
  scaled.solution_scaled_tolerance = true;  // resolve lambda relative to itself, not to |e - g|
  const MprgpResult qp = solve_mprgp(*compliance_, right_hand_side, lower, warm_start_, scaled);

  ContactSolveResult result = contact_solve_result(qp, obstacle);
  if (qp.status == QpStatus::converged) warm_start_ = qp.solution;
  result.seconds = seconds_since(start);
  return result;
}

ContactSolveResult BodySolver::solve_primal_contact(const Eigen::VectorXd& obstacle) {
  const auto start = std::chrono::steady_clock::now();
  // B (u_f + u_p) <= g  <=>  B u_f <= g - t B u_p;  the load t f
  const Eigen::VectorXd bound = obstacle - load_factor_ * prescribed_trace_;
  const PrimalContactResult primal =
      robin::solve_primal_contact(*multigrid_, trace_, load_factor_ * reduced_load_, bound,
                                  load_factor_ * free_solution_, *primal_state_);
  ContactSolveResult result = contact_solve_result(primal, obstacle);
  result.seconds = seconds_since(start);
  return result;
}

Eigen::VectorXd BodySolver::solve_correction(const Eigen::VectorXd& interface_force,
                                             double relative_accuracy) const {
  if (interface_force.size() != contact_size()) {
    throw InputError("body '" + name() + "': interface force has " +
                     std::to_string(interface_force.size()) + " values for " +
                     std::to_string(contact_size()) + " contact nodes");
  }
  if (!(relative_accuracy >= 0.0 && relative_accuracy < 1.0)) {
    throw InputError("body '" + name() + "': relative accuracy " +
                     std::to_string(relative_accuracy) + " of a correction outside [0, 1)");
  }
  Eigen::VectorXd trace;
  if (rigid_mode_count() > 0) {
    // w_N = B K^dagger B' r = B P K^+ P B' r, P = I - R R'
    return trace_ * factor_->solve_minimum_norm(apply_transpose_trace(interface_force));
  }
  if (multigrid_) {
    // To the accuracy of the contact solves: relative to the larger of B'r and the last contact
    // force B'lambda, so that the small r of a nearly converged coupling costs few iterations.
    const Eigen::VectorXd load = apply_transpose_trace(interface_force);
    const double load_norm = load.norm();
    const double contact_load_norm =
        primal_state_->contact_force.size() == contact_size()
            ? apply_transpose_trace(primal_state_->contact_force).norm()
            : 0.0;
    if (load_norm == 0.0) return Eigen::VectorXd::Zero(contact_size());
    const double tolerance = std::max(
        multigrid_->relative_tolerance() * std::max(load_norm, contact_load_norm) / load_norm,
        relative_accuracy);
    const Eigen::VectorXd solution = multigrid_->solve(
        load, correction_history_.start(interface_force, free_dof_count()), tolerance);
    Eigen::VectorXd correction = trace_ * solution;
    if (relative_accuracy == 0.0) correction_history_.add(interface_force, solution, correction);
    return correction;
  }
  compliance_->apply(interface_force, trace);  // w_N = B K^{-1} B' r
  return trace;
}

Eigen::VectorXd BodySolver::solve_neumann(const Eigen::VectorXd& contact_force) const {
  if (rigid_mode_count() > 0) {
    throw SingularBodyError("body '" + name() + "' is a floating body (" +
                            std::to_string(rigid_mode_count()) +
                            " rigid motions free): its Neumann solve K u = f - B' lambda has no "
                            "solution for a contact force that does not balance its loads; it "
                            "must solve the contact problem instead");
  }
  return free_trace_ - solve_correction(contact_force);  // e - F lambda
}

Eigen::VectorXd BodySolver::apply_transpose_trace(const Eigen::VectorXd& contact_force) const {
  return trace_.transpose() * contact_force;
}

Eigen::VectorXd BodySolver::displacement(const Eigen::VectorXd& contact_force) const {
  return displacement(contact_force, rigid_amplitudes_);
}

Eigen::VectorXd BodySolver::displacement(const Eigen::VectorXd& contact_force,
                                         const Eigen::VectorXd& rigid_amplitudes) const {
  // u_f = K^{-1} (t f - B' lambda) (+ R alpha with K^+), u_p = t u_p1 (t the load factor)
  Eigen::VectorXd free_values = load_factor_ * free_solution_;
  if (primal_state_ && primal_state_->contact_force.size() == contact_force.size() &&
      contact_force.size() > 0 && primal_state_->contact_force == contact_force) {
    free_values = primal_state_->displacement;  // the last primal contact solve's u
  } else if (multigrid_ && primal_state_ && contact_force.size() == contact_size() &&
             primal_state_->displacement.size() == free_dof_count()) {
    // K u = t f - B' lambda from the last contact solve's u and correction
    free_values =
        multigrid_->solve(load_factor_ * reduced_load_ - apply_transpose_trace(contact_force),
                          displacement_guess(contact_force));
  } else if (contact_force.size() > 0 && contact_force.lpNorm<Eigen::Infinity>() > 0) {
    free_values -= solve_stiffness(apply_transpose_trace(contact_force));
  }
  if (rigid_mode_count() > 0) {
    if (rigid_amplitudes.size() != rigid_mode_count()) {
      throw InputError("body '" + name() + "': " + std::to_string(rigid_amplitudes.size()) +
                       " rigid amplitudes for " + std::to_string(rigid_mode_count()) +
                       " rigid motions");
    }
    free_values += rigid_modes() * rigid_amplitudes;
  }
  Eigen::VectorXd full = dofs_->expand(free_values);  // prescribed values at factor 1
  if (load_factor_ != 1.0) full += (load_factor_ - 1.0) * dofs_->prescribed_values();
  return full;
}

Eigen::VectorXd BodySolver::displacement_guess(const Eigen::VectorXd& contact_force) const {
  const Eigen::VectorXd& contact_displacement = primal_state_->displacement;
  const Eigen::VectorXd& contact_solution_force = primal_state_->contact_force;  // lambda_u
  if (contact_solution_force.size() != contact_force.size()) return contact_displacement;
  // K^{-1} (t f - B' lambda) = u + K^{-1} B' (lambda_u - lambda)
  return contact_displacement +
         correction_history_.start(contact_solution_force - contact_force, free_dof_count());
}

Eigen::VectorXd BodySolver::reactions(const Eigen::VectorXd& displacement) const {
  // (K u)_p = K_p: u: the prescribed part holds the whole of every prescribed row
  Eigen::VectorXd reaction = prescribed_stiffness_ * displacement - load_factor_ * full_load_;
  for (int dof = 0; dof < dofs_->total_count(); ++dof) {
    if (!dofs_->is_prescribed(dof)) reaction[dof] = 0.0;
  }
  return reaction;
}

Eigen::Vector3d BodySolver::applied_force() const {
  const int dimension = definition_.mesh.dimension;
  Eigen::Vector3d total = Eigen::Vector3d::Zero();
  for (Eigen::Index node = 0; node < full_load_.size() / dimension; ++node) {
    total.head(dimension) += full_load_.segment(dimension * node, dimension);
  }
  return load_factor_ * total;
}

Eigen::VectorXd BodySolver::contact_force_field(const Eigen::VectorXd& contact_force) const {
  Eigen::VectorXd field = Eigen::VectorXd::Zero(dofs_->total_count());
  for (int row = 0; row < contact_size(); ++row) {
    for (std::size_t k = contact_.row_offsets[row]; k < contact_.row_offsets[row + 1]; ++k) {
      field[definition_.mesh.dimension * contact_.nodes[k] + contact_.components[k]] -=
          contact_.values[k] * contact_force[row];
    }
  }
  return field;
}

}  // namespace robin
