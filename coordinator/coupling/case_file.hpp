#pragma once
// The TOML case format (docs/case-format.md): the bodies (two, or N >= 2 with their contact
// interfaces in [[interface]] tables), an optional gap function, solver and coupling options.
// Unknown keys are errors.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "coupling/acceleration.hpp"
#include "coupling/case_file_loading.hpp"
#include "coupling/case_file_reference.hpp"
#include "coupling/contact_discretization.hpp"
#include "coupling/contact_interface.hpp"
#include "coupling/coupling_choices.hpp"
#include "numerics/body_definition.hpp"
#include "numerics/body_solver.hpp"
#include "numerics/gmsh_reader.hpp"
#include "numerics/mprgp.hpp"

namespace robin {

/// A boundary name a body refers to, and where the case file gives it (for messages).
struct BoundaryReference {
  std::string name;      // the physical curve name
  std::string field;     // full key path, e.g. "body[2].dirichlet[1].boundary"
  std::string location;  // "case.toml:31" (file:line of the value)
};

/// How a body's mesh reaches its server.
enum class MeshDelivery {
  /// The coordinator reads (or meshes) the file and sends the mesh as data (SetupBody.mesh).
  data,
  /// The server reads the .msh file itself (SetupBody.mesh_path: the file's name, under the
  /// data directory its launcher gave it, the file's directory); the coordinator reads only
  /// the file's head for its checks (summarize_msh_file). load_meshes turns it into `data` when
  /// that head cannot vouch for them (no summary, another dimension, a boundary name it does
  /// not list), so that the full read gives its exact error.
  file_on_server,
};

/// One body as written in the case file. `definition.mesh` is empty until load_meshes, and
/// stays empty when the server reads the file (MeshDelivery::file_on_server).
struct BodyCase {
  BodyDefinition definition;
  std::filesystem::path mesh_path;  // absolute (resolved against the case file's directory)
  MeshReadOptions mesh_options;
  std::string context;  // "case.toml: body 'upper'" for messages
  /// "case.toml:27: body 'upper': body[2].mesh", where the mesh is named (for mesh errors:
  /// Gmsh syntax errors, meshes without physical groups); empty for a BodyCase built by hand.
  std::string mesh_context;
  /// contact_boundary (or the body's boundaries in [[interface]] tables), then every dirichlet
  /// and traction boundary, in file order. When empty
  /// (a BodyCase built by hand), load_body checks the names in `definition` instead.
  std::vector<BoundaryReference> boundary_references;
  /// [[body]] floating = true: contact alone may hold the body (its supports may leave rigid
  /// motions free; docs/method.md, "Floating bodies"). false: such a body is an error.
  bool floating = false;
  /// The case's dimension: 2 (a plane body) or 3 (a solid one); its mesh must have it.
  int dimension = 2;
  MeshDelivery mesh_delivery = MeshDelivery::data;
  /// file_on_server: SetupBody.mesh_path, the file's name under the server's data directory.
  std::string server_mesh_path;
  /// file_on_server: the file's node count (summarize_msh_file), for the solver's choice.
  std::uint64_t mesh_file_node_count = 0;
};

/// Options of the Robin iteration (coordinator); command-line flags override them.
struct CouplingOptions {
  /// The coupling algorithm (coupling/coupling_scheme.hpp): "robin" (the paper's (Q_m)),
  /// "robin-constant", "dirichlet-neumann" or "neumann-neumann".
  CouplingAlgorithm algorithm = CouplingAlgorithm::robin;
  /// "robin-constant": the constant alpha_S of paper (6) (length per pressure; > 0).
  double alpha = 0.0;
  /// "dirichlet-neumann": the body that solves the contact problem, "1", "2" or "auto" (the
  /// more compliant body, measured by one correction solve each).
  ContactBodyChoice contact_body = ContactBodyChoice::automatic;
  /// "either-sequence": stop also when one obstacle sequence's complete state converged
  /// ("robin"); "joint": only when the joint state of both sequences did (the paper's test).
  StoppingRule stopping = StoppingRule::either_sequence;
  double relaxation = 0.5;  // delta of paper (13), for both bodies unless overridden
  std::optional<double> relaxation1, relaxation2;  // per-body deltas (default: relaxation)
  /// Acceleration of the obstacle update (method "iqn-ils", "aitken" or "none"; see
  /// coupling/acceleration.hpp). Its relaxation1/2 are filled from the fields above by
  /// effective_acceleration().
  AccelerationOptions acceleration;
  double tolerance = 1e-8;  // on every scaled residual
  int max_iterations = 200;
  InitialObstacle initial_obstacle = InitialObstacle::gap;  // "gap": g^alpha_0 = d; "zero": 0
  double request_timeout_seconds = 60.0;  // deadline of each interface-sized request
  /// Deadline of the mesh-sized requests (setup: meshing, assembly, factorization and the
  /// interface operator; fields), which grow with the body while the others do not.
  double setup_timeout_seconds = 3600.0;
  double divergence_factor = 1e3;  // obstacle-step growth over its minimum: divergence
  int stagnation_window = 50;      // iterations without residual decrease that mean stagnation
};

struct SolverOptions {
  MprgpParameters qp;
  BodySolverOptions body;
  double pairing_tolerance = 1e-6;  // relative to the shortest contact edge
};

/// One [[interface]] table (or the one interface of a two-body case without them).
struct InterfaceCase {
  InterfaceDefinition definition;  // bodies (indices into CaseDefinition::bodies), boundaries
  std::string context;             // "case.toml:41: interface[2]" for messages
};

/// The solver options of one body: `solver`'s, with its rigid motions held by contact when the
/// body is floating (otherwise as `solver` says: refused, unless a caller asked otherwise).
BodySolverOptions body_solver_options(const SolverOptions& solver, const BodyCase& body);

/// The most bodies a case may have.
inline constexpr std::size_t maximum_body_count = 256;

struct CaseDefinition {
  std::filesystem::path file;
  std::string title;
  /// `dimension` = 2 (plane bodies, the default) or 3 (solid bodies): every body's mesh, vectors
  /// and material are of this dimension.
  int dimension = 2;
  /// Two or more bodies, in file order; body alpha's definition.contact_boundaries are the
  /// boundaries its interfaces name, in interface order, each once.
  std::vector<BodyCase> bodies;
  /// The contact interfaces, at least one; every body is in at least one.
  std::vector<InterfaceCase> interfaces;
  std::optional<std::string> gap_expression;
  std::map<std::string, double> gap_constants;
  std::string gap_context;  // "case.toml:12: gap.expression", the GapFunction context
  SolverOptions solver;
  CouplingOptions coupling;
  ContactOptions contact;  // [contact]: node-to-node or mortar (interfaces may override it)
  /// The command-line overrides applied to the file, in order, as given ("KEY=VALUE", see
  /// case_file_overrides.hpp); empty when the file is read as it is.
  std::vector<std::string> overrides;
  LoadingOptions loading;  // [loading]: quasi-static load steps (none: one solve at factor 1)
  std::optional<ReferenceSolution> reference;  // [reference]: an analytic solution, for plots
  /// Not from the file: told as load_meshes meshes or reads each body's mesh (the request index
  /// is the body's index), for the tools' progress lines. Empty: nobody is told.
  MeshReadObserver meshing;
};

/// The acceleration options with the per-body relaxations resolved (relaxation1/2, else
/// relaxation).
AccelerationOptions effective_acceleration(const CouplingOptions& options);

/// The interfaces of `definition` as the contact graph's coupling takes them. An interface whose
/// non-mortar side is "auto" between a floating and a supported body gets the floating body as
/// its non-mortar side.
std::vector<InterfaceDefinition> interface_definitions(const CaseDefinition& definition);
/// The body names, in body order.
std::vector<std::string> body_names(const CaseDefinition& definition);

/// `message` about the case in `case_file`, prefixed with the file's path unless it already
/// names it (errors raised after reading: a body left with a rigid motion, unmatched contact
/// nodes), so that every error names the file.
std::string in_case_file(const std::filesystem::path& case_file, const std::string& message);

/// Parses and validates a case file (without reading meshes): every key, type and range,
/// the materials, the existence of the mesh files, and the gap expression (parsed and
/// evaluated once). Throws InputError naming the file, line and field (and the body).
/// The title defaults to the file's stem. `overrides` ("KEY=VALUE", case_file_overrides.hpp)
/// are applied to the parsed file first, so every check applies to their values; errors about
/// them name the override, other errors list the overrides.
CaseDefinition read_case_file(const std::filesystem::path& path,
                              const std::vector<std::string>& overrides = {});

/// Reads the body's mesh and checks every boundary name against it; returns the complete
/// definition. Throws InputError naming the case file, body, field and mesh file and listing
/// the mesh's boundary names; a mesh reader error is rethrown with `context` prepended.
BodyDefinition load_body(const BodyCase& body);

/// Reads every body's mesh into its definition at once (read_gmsh_meshes: each .geo meshed in a
/// process of its own, concurrently; definition.meshing is told as it goes) and checks every
/// boundary name, as load_body does.
void load_meshes(CaseDefinition& definition);

/// load_meshes, telling `loaded(k)` on the calling thread as soon as body k's mesh is in its
/// definition and checked, while the other meshes are still being read or meshed. Bodies whose
/// meshes arrive are told even when another body's mesh fails later (and the call throws).
void load_meshes(CaseDefinition& definition, const std::function<void(std::size_t body)>& loaded);

}  // namespace robin
