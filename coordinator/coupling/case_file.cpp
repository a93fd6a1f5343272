#include "coupling/case_file.hpp"

#include <algorithm>
#include <cctype>
#include <functional>
#include <optional>

#include "coupling/case_file_body.hpp"
#include "coupling/case_file_interface.hpp"
#include "coupling/case_file_loading.hpp"
#include "coupling/case_file_overrides.hpp"
#include "coupling/case_file_table.hpp"
#include "coupling/gap_function.hpp"
#include "numerics/errors.hpp"
#include "numerics/msh_file.hpp"

namespace robin {

namespace {

const std::vector<std::string> root_keys{"title",     "dimension", "gap",  "solver",
                                         "coupling",  "contact",   "body", "loading",
                                         "reference", "interface"};
const std::vector<std::string> contact_keys{"method", "non_mortar"};
const std::vector<std::string> gap_keys{"expression", "constants"};
const std::vector<std::string> solver_keys{"qp_tolerance",       "qp_max_iterations",
                                           "interface_operator", "dense_limit",
                                           "linear_solver",      "pairing_tolerance"};
const std::vector<std::string> coupling_keys{"relaxation",
                                             "tolerance",
                                             "max_iterations",
                                             "initial_obstacle",
                                             "request_timeout",
                                             "setup_timeout",
                                             "divergence_factor",
                                             "stagnation_window",
                                             "acceleration",
                                             "relaxation1",
                                             "relaxation2",
                                             "aitken_initial",
                                             "aitken_minimum",
                                             "aitken_maximum",
                                             "history_depth",
                                             "filter_threshold",
                                             "safeguard_growth",
                                             "per_body",
                                             "mixing",
                                             "algorithm",
                                             "alpha",
                                             "contact_body",
                                             "stopping"};

toml::table parse_toml(const std::filesystem::path& path, const std::string& label) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(label + ": case file not found (resolved to '" +
                     std::filesystem::absolute(path).lexically_normal().string() + "')");
  }
  try {
    return toml::parse_file(path.string());
  } catch (const toml::parse_error& parse_error) {
    const auto& begin = parse_error.source().begin;
    throw InputError(label + ":" + std::to_string(begin.line) + ":" + std::to_string(begin.column) +
                     ": TOML syntax error: " + std::string(parse_error.description()));
  }
}

/// The value of `key` when present, checked to be > lower; `fallback` when absent.
double number_above(const CheckedTable& table, std::string_view key, double lower,
                    double fallback) {
  const auto value = table.optional_number(key);
  if (!value) return fallback;
  if (!(*value > lower)) {
    table.fail(key, "must be > " + format_number(lower) + ", got " + format_number(*value));
  }
  return *value;
}

int integer_at_least(const CheckedTable& table, std::string_view key, int lower, int fallback) {
  const auto value = table.optional_integer(key);
  if (!value) return fallback;
  if (*value < lower) {
    table.fail(key, "must be >= " + std::to_string(lower) + ", got " + std::to_string(*value));
  }
  return *value;
}

bool is_valid_constant_name(const std::string& name) {
  const auto is_word = [](unsigned char c) { return std::isalnum(c) != 0 || c == '_'; };
  return !name.empty() && std::isdigit(static_cast<unsigned char>(name.front())) == 0 &&
         std::all_of(name.begin(), name.end(), is_word);
}

void read_gap(const CheckedTable& root, CaseDefinition& definition) {
  const auto table = root.optional_table("gap", gap_keys);
  if (!table) return;
  definition.gap_expression = table->string("expression");
  definition.gap_constants = table->number_map("constants");
  for (const auto& [name, value] : definition.gap_constants) {
    if (!is_valid_constant_name(name)) {
      table->fail("constants", "'" + name +
                                   "' is not a valid constant name (a letter or '_', then "
                                   "letters, digits or '_')");
    }
    if (name == "x" || name == "y" || name == "z") {
      table->fail("constants", "'" + name + "' is a variable of the expression, not a constant");
    }
  }
  definition.gap_context = table->location("expression") + ": " + table->field("expression");
  // Parses and evaluates once: a bad expression is reported here, with its line.
  const GapFunction validation(*definition.gap_expression, definition.gap_constants,
                               definition.gap_context);
}

/// dimension = 2 (plane bodies, the default) or 3 (solid bodies).
int read_dimension(const CheckedTable& root) {
  const auto dimension = root.optional_integer("dimension");
  if (dimension && *dimension != 2 && *dimension != 3) {
    root.fail("dimension",
              "must be 2 (plane bodies) or 3 (solid bodies), got " + std::to_string(*dimension));
  }
  return dimension.value_or(2);
}

void read_solver(const CheckedTable& root, SolverOptions& solver) {
  const auto table = root.optional_table("solver", solver_keys);
  if (!table) return;
  solver.qp.relative_tolerance =
      number_above(*table, "qp_tolerance", 0.0, solver.qp.relative_tolerance);
  solver.qp.max_iterations =
      integer_at_least(*table, "qp_max_iterations", 1, solver.qp.max_iterations);
  if (const auto kind = table->optional_choice("interface_operator", {"auto", "dense", "factor"})) {
    solver.body.interface_operator = *kind == "auto"    ? InterfaceOperatorKind::automatic
                                     : *kind == "dense" ? InterfaceOperatorKind::dense
                                                        : InterfaceOperatorKind::factor;
  }
  solver.body.dense_limit = integer_at_least(*table, "dense_limit", 1, solver.body.dense_limit);
  if (const auto kind = table->optional_choice("linear_solver", {"auto", "direct", "multigrid"})) {
    solver.body.linear_solver = *kind == "auto"        ? LinearSolverKind::automatic
                                : *kind == "multigrid" ? LinearSolverKind::multigrid
                                                       : LinearSolverKind::direct;
  }
  solver.pairing_tolerance =
      number_above(*table, "pairing_tolerance", 0.0, solver.pairing_tolerance);
}

void read_contact(const CheckedTable& root, ContactOptions& contact) {
  const auto table = root.optional_table("contact", contact_keys);
  if (!table) return;
  if (const auto method =
          table->optional_choice("method", {"auto", "node-to-node", "mortar", "node-to-segment"})) {
    contact.method = *method == "node-to-node"      ? ContactMethod::node_to_node
                     : *method == "mortar"          ? ContactMethod::mortar
                     : *method == "node-to-segment" ? ContactMethod::node_to_segment
                                                    : ContactMethod::automatic;
  }
  contact.non_mortar = table->optional_string("non_mortar").value_or("");
  if (contact.non_mortar == "auto") contact.non_mortar.clear();
}

/// A relaxation factor delta in (0, 2), or nothing when the key is absent.
std::optional<double> optional_relaxation(const CheckedTable& table, std::string_view key) {
  const auto value = table.optional_number(key);
  if (value && !(*value > 0.0 && *value < 2.0)) {
    table.fail(key, "must be in (0, 2), got " + format_number(*value));
  }
  return value;
}

/// The choice `key` names, when the table has it: one of the texts of coupling_choices.hpp,
/// which the error lists otherwise.
template <OptionChoice Choice>
std::optional<Choice> optional_choice(const CheckedTable& table, std::string_view key) {
  const std::optional<std::string> text = table.optional_choice(key, choice_texts<Choice>());
  if (!text) return std::nullopt;
  return choice_from_text<Choice>(*text).value();
}

/// The acceleration keys of [coupling]; the ranges are those of validate(AccelerationOptions).
void read_acceleration(const CheckedTable& table, CouplingOptions& coupling) {
  AccelerationOptions& acceleration = coupling.acceleration;
  acceleration.method =
      optional_choice<AccelerationMethod>(table, "acceleration").value_or(acceleration.method);
  coupling.relaxation1 = optional_relaxation(table, "relaxation1");
  coupling.relaxation2 = optional_relaxation(table, "relaxation2");
  acceleration.aitken_initial =
      table.optional_number("aitken_initial").value_or(acceleration.aitken_initial);
  acceleration.aitken_minimum =
      number_above(table, "aitken_minimum", 0.0, acceleration.aitken_minimum);
  acceleration.aitken_maximum =
      number_above(table, "aitken_maximum", 0.0, acceleration.aitken_maximum);
  acceleration.history_depth =
      integer_at_least(table, "history_depth", 1, acceleration.history_depth);
  acceleration.filter_threshold =
      number_above(table, "filter_threshold", 0.0, acceleration.filter_threshold);
  acceleration.safeguard_growth =
      number_above(table, "safeguard_growth", 1.0, acceleration.safeguard_growth);
  acceleration.per_body = table.optional_boolean("per_body").value_or(acceleration.per_body);
  acceleration.mixing =
      optional_choice<QuasiNewtonMixing>(table, "mixing").value_or(acceleration.mixing);
  try {
    validate(effective_acceleration(coupling));
  } catch (const InputError& error) {
    table.fail("acceleration", error.what());
  }
}

/// The algorithm keys of [coupling] (coupling/coupling_scheme.hpp).
void read_algorithm(const CheckedTable& table, CouplingOptions& coupling) {
  coupling.algorithm =
      optional_choice<CouplingAlgorithm>(table, "algorithm").value_or(coupling.algorithm);
  coupling.alpha = number_above(table, "alpha", 0.0, coupling.alpha);
  if (coupling.algorithm == CouplingAlgorithm::robin_constant && !(coupling.alpha > 0.0)) {
    table.fail("algorithm",
               "\"robin-constant\" needs coupling.alpha > 0 (the constant alpha_S, "
               "length per pressure)");
  }
  coupling.contact_body =
      optional_choice<ContactBodyChoice>(table, "contact_body").value_or(coupling.contact_body);
  coupling.stopping = optional_choice<StoppingRule>(table, "stopping").value_or(coupling.stopping);
}

void read_coupling(const CheckedTable& root, CouplingOptions& coupling) {
  const auto table = root.optional_table("coupling", coupling_keys);
  if (!table) return;
  coupling.relaxation = table->optional_number("relaxation").value_or(coupling.relaxation);
  if (!(coupling.relaxation > 0.0 && coupling.relaxation < 2.0)) {
    table->fail("relaxation", "must be in (0, 2), got " + format_number(coupling.relaxation));
  }
  coupling.tolerance = number_above(*table, "tolerance", 0.0, coupling.tolerance);
  coupling.max_iterations = integer_at_least(*table, "max_iterations", 1, coupling.max_iterations);
  coupling.initial_obstacle = optional_choice<InitialObstacle>(*table, "initial_obstacle")
                                  .value_or(coupling.initial_obstacle);
  coupling.request_timeout_seconds =
      number_above(*table, "request_timeout", 0.0, coupling.request_timeout_seconds);
  coupling.setup_timeout_seconds =
      number_above(*table, "setup_timeout", 0.0, coupling.setup_timeout_seconds);
  coupling.divergence_factor =
      number_above(*table, "divergence_factor", 1.0, coupling.divergence_factor);
  coupling.stagnation_window =
      integer_at_least(*table, "stagnation_window", 1, coupling.stagnation_window);
  read_acceleration(*table, coupling);
  read_algorithm(*table, coupling);
}

/// The [[body]] tables: exactly two without [[interface]] tables, 2 to maximum_body_count with
/// them; names unique. Returns the entries (for the lines of later messages).
std::vector<TableEntry> read_bodies(const CheckedTable& root,
                                    const std::filesystem::path& directory,
                                    CaseDefinition& definition) {
  const std::vector<TableEntry> entries = root.array_of_tables("body");
  const bool graph = root.contains("interface");
  const std::size_t most = graph ? maximum_body_count : 2;
  if (entries.size() < 2 || entries.size() > most) {
    const int line = entries.size() > most   ? line_of(*entries[most].table)
                     : root.contains("body") ? root.line("body")
                                             : 0;
    const std::string expected =
        graph ? "between two and " + std::to_string(most) + " [[body]] tables"
              : std::string("exactly two [[body]] tables");
    const std::string hint = graph || entries.size() < 2
                                 ? ""
                                 : " (a case of more bodies names its contact interfaces in "
                                   "[[interface]] tables)";
    throw InputError(root.context().prefix(line) + ": expected " + expected + ", found " +
                     std::to_string(entries.size()) + hint);
  }
  const ContactBoundaryKey contact_key =
      graph ? ContactBoundaryKey::refused : ContactBoundaryKey::required;
  for (std::size_t index = 0; index < entries.size(); ++index) {
    definition.bodies.push_back(read_body_case(entries[index], root.context(), directory,
                                               contact_key, definition.dimension));
    for (std::size_t earlier = 0; earlier < index; ++earlier) {
      if (definition.bodies[earlier].definition.name != definition.bodies[index].definition.name)
        continue;
      CaseContext context = root.context();
      context.body = definition.bodies[index].definition.name;
      throw InputError(context.prefix(line_of(*(*entries[index].table).get("name"))) + ": body[" +
                       std::to_string(index + 1) + "].name: duplicates the name of body[" +
                       std::to_string(earlier + 1) + "]; body names must differ");
    }
  }
  return entries;
}

std::string join_boundary_names(const Mesh& mesh) {
  std::string names;
  for (const auto& [name, group] : mesh.boundaries) names += (names.empty() ? "" : ", ") + name;
  return names.empty() ? "none: the mesh has no physical curves" : names;
}

std::vector<BoundaryReference> references_of(const BodyDefinition& definition) {
  std::vector<BoundaryReference> references;
  const std::vector<std::string>& contact = definition.contact_boundaries;
  for (std::size_t i = 0; i < contact.size(); ++i) {
    // one contact boundary: the case file's key; several (hand-built): numbered like the others
    references.push_back({contact[i],
                          contact.size() == 1 ? std::string("contact_boundary")
                                              : "contact_boundaries[" + std::to_string(i + 1) + "]",
                          ""});
  }
  for (std::size_t i = 0; i < definition.dirichlet.size(); ++i) {
    references.push_back({definition.dirichlet[i].boundary,
                          "dirichlet[" + std::to_string(i + 1) + "].boundary", ""});
  }
  for (std::size_t i = 0; i < definition.tractions.size(); ++i) {
    references.push_back(
        {definition.tractions[i].boundary, "traction[" + std::to_string(i + 1) + "].boundary", ""});
  }
  return references;
}

}  // namespace

AccelerationOptions effective_acceleration(const CouplingOptions& options) {
  AccelerationOptions acceleration = options.acceleration;
  acceleration.relaxation1 = options.relaxation1.value_or(options.relaxation);
  acceleration.relaxation2 = options.relaxation2.value_or(options.relaxation);
  return acceleration;
}

BodySolverOptions body_solver_options(const SolverOptions& solver, const BodyCase& body) {
  BodySolverOptions options = solver.body;
  if (body.floating) options.rigid_motions = RigidMotions::held_by_contact;
  return options;
}

std::vector<InterfaceDefinition> interface_definitions(const CaseDefinition& definition) {
  std::vector<InterfaceDefinition> interfaces;
  for (const InterfaceCase& interface : definition.interfaces) {
    InterfaceDefinition coupled = interface.definition;
    ContactOptions contact = coupled.contact.value_or(definition.contact);
    const bool floating_a = definition.bodies.at(static_cast<std::size_t>(coupled.body_a)).floating;
    const bool floating_b = definition.bodies.at(static_cast<std::size_t>(coupled.body_b)).floating;
    if (contact.non_mortar.empty() && floating_a != floating_b) {
      // A floating body takes the obstacles of its interfaces (docs/method.md, "Floating
      // bodies"): its rows must be its own nodes, or its dual has more rows than its trace has
      // degrees of freedom there (a singular F, a contact force that is not unique).
      const int floating = floating_a ? coupled.body_a : coupled.body_b;
      contact.non_mortar = definition.bodies[static_cast<std::size_t>(floating)].definition.name;
      coupled.contact = contact;
    }
    interfaces.push_back(std::move(coupled));
  }
  return interfaces;
}

std::vector<std::string> body_names(const CaseDefinition& definition) {
  std::vector<std::string> names;
  for (const BodyCase& body : definition.bodies) names.push_back(body.definition.name);
  return names;
}

/// read_case_file without the mention of the overrides in its errors.
static CaseDefinition read_case_document(const std::filesystem::path& path,
                                         const std::vector<std::string>& overrides) {
  const std::string label = path.string();
  toml::table document = parse_toml(path, label);
  CaseContext context{label, ""};
  context.override_lines = apply_case_overrides(document, path, overrides);  // --set KEY=VALUE
  const CheckedTable root(document, "", context, root_keys);
  CaseDefinition definition;
  definition.file = path;
  definition.overrides = overrides;
  definition.title = root.optional_string("title").value_or(path.stem().string());
  definition.dimension = read_dimension(root);
  read_gap(root, definition);
  read_solver(root, definition.solver);
  read_coupling(root, definition.coupling);
  read_contact(root, definition.contact);
  definition.loading = read_loading(root);  // [loading]: coupling/case_file_loading.hpp
  const std::vector<TableEntry> bodies = read_bodies(root, path.parent_path(), definition);
  const std::vector<std::string> names = body_names(definition);
  if (!definition.contact.non_mortar.empty() &&
      std::find(names.begin(), names.end(), definition.contact.non_mortar) == names.end()) {
    const auto table = root.optional_table("contact", contact_keys);
    table->fail("non_mortar",
                "'" + definition.contact.non_mortar + "' is not the name of a body (nor \"auto\")");
  }
  read_interfaces(root, bodies, definition);  // [[interface]]: coupling/case_file_interface.hpp
  definition.reference =
      read_reference(root, definition.dimension);  // after the bodies: their materials give E*
  return definition;
}

CaseDefinition read_case_file(const std::filesystem::path& path,
                              const std::vector<std::string>& overrides) {
  try {
    return read_case_document(path, overrides);
  } catch (const InputError& error) {
    throw InputError(mention_overrides(error.what(), overrides));
  }
}

namespace {

/// Checks every boundary name of `body` against its loaded mesh.
void check_boundary_names(const BodyCase& body, const BodyDefinition& definition) {
  const std::vector<BoundaryReference> references =
      body.boundary_references.empty() ? references_of(definition) : body.boundary_references;
  for (const BoundaryReference& reference : references) {
    if (definition.mesh.boundaries.count(reference.name) != 0) continue;
    const std::string where = reference.location.empty()
                                  ? body.context
                                  : reference.location + ": body '" + definition.name + "'";
    throw InputError(where + ": " + reference.field + ": boundary '" + reference.name +
                     "' is not a physical curve of mesh '" + body.mesh_path.string() +
                     "' (available: " + join_boundary_names(definition.mesh) + ")");
  }
}

/// "case.toml:27: body 'upper': body[2].mesh" (or "case.toml: body 'upper': mesh").
std::string mesh_context(const BodyCase& body) {
  return body.mesh_context.empty() ? body.context + ": mesh" : body.mesh_context;
}

/// The InputError of a mesh reader, with the context of the body whose file it names.
InputError mesh_error(const std::vector<BodyCase*>& bodies, const InputError& error) {
  const std::string message = error.what();
  for (const BodyCase* body : bodies) {
    if (message.find(body->mesh_path.string()) != std::string::npos) {
      return InputError(mesh_context(*body) + ": " + message);
    }
  }
  return error;
}

/// The body's mesh is of the case's dimension (a plane mesh in a case of plane bodies, a solid
/// one with dimension = 3).
void require_mesh_dimension(const BodyCase& body, const Mesh& mesh) {
  if (mesh.dimension == body.dimension) return;
  const std::string hint = mesh.dimension == 3
                               ? "set dimension = 3 at the top of the case file for solid bodies "
                                 "(and remove the plane model)"
                               : "a case with dimension = 3 takes solid (volume) meshes only";
  throw InputError(mesh_context(body) + ": mesh '" + body.mesh_path.string() + "' is " +
                   (mesh.dimension == 3 ? "three-dimensional (volume elements)"
                                        : "two-dimensional (area elements)") +
                   " but the case file has dimension = " + std::to_string(body.dimension) + ": " +
                   hint);
}

}  // namespace

BodyDefinition load_body(const BodyCase& body) {
  BodyDefinition definition = body.definition;
  try {
    definition.mesh = read_gmsh_mesh(body.mesh_path, body.mesh_options);
  } catch (const InputError& error) {
    throw InputError(mesh_context(body) + ": " + error.what());
  }
  require_mesh_dimension(body, definition.mesh);
  check_boundary_names(body, definition);
  return definition;
}

namespace {

/// `observer` told of the requests whose bodies are `body_indices` by body index.
MeshReadObserver for_bodies(const MeshReadObserver& observer,
                            const std::vector<std::size_t>& body_indices) {
  MeshReadObserver translated = observer;
  if (observer.started) {
    translated.started = [&observer, &body_indices](std::size_t request) {
      observer.started(body_indices[request]);
    };
  }
  if (observer.finished) {
    translated.finished = [&observer, &body_indices](std::size_t request, const Mesh& mesh,
                                                     double seconds) {
      observer.finished(body_indices[request], mesh, seconds);
    };
  }
  return translated;
}

/// Whether the head of `body`'s .msh file vouches for the checks load_body makes (its dimension,
/// every boundary name the body refers to), so that its server may read the file itself; sets
/// the body's node count. The full read gives the exact error of a file it does not vouch for.
bool head_vouches_for(BodyCase& body) {
  const MeshReadOptions defaults;
  if (body.mesh_options.size != defaults.size ||
      body.mesh_options.element_order != defaults.element_order ||
      body.mesh_options.recombine != defaults.recombine) {
    return false;  // options of a .geo: the full read refuses them
  }
  std::optional<MshSummary> summary;
  try {
    summary = summarize_msh_file(body.mesh_path);
  } catch (const InputError&) {
    return false;
  }
  if (!summary || summary->dimension != body.dimension) return false;
  const std::vector<BoundaryReference> references =
      body.boundary_references.empty() ? references_of(body.definition) : body.boundary_references;
  for (const BoundaryReference& reference : references) {
    const std::vector<std::string>& names = summary->boundary_names;
    if (std::find(names.begin(), names.end(), reference.name) == names.end()) return false;
  }
  body.mesh_file_node_count = summary->node_count;
  return true;
}

}  // namespace

void load_meshes(CaseDefinition& definition, const std::function<void(std::size_t)>& loaded) {
  std::vector<BodyCase*> bodies;  // the bodies whose meshes are read here, request by request
  std::vector<std::size_t> body_indices;
  std::vector<MeshFileRequest> requests;
  std::vector<std::size_t> read_by_servers;
  for (std::size_t k = 0; k < definition.bodies.size(); ++k) {
    BodyCase& body = definition.bodies[k];
    if (body.mesh_delivery == MeshDelivery::file_on_server) {
      if (head_vouches_for(body)) {
        read_by_servers.push_back(k);
        continue;
      }
      body.mesh_delivery = MeshDelivery::data;
    }
    bodies.push_back(&body);
    body_indices.push_back(k);
    requests.push_back({body.mesh_path, body.mesh_options});
  }
  if (loaded) {  // these setups begin at once, while the coordinator reads the other meshes
    for (const std::size_t k : read_by_servers) loaded(k);
  }
  // a body's checks fail after the reading of every mesh, in body order (a reader's error first)
  std::vector<std::optional<InputError>> unusable(bodies.size());
  const auto receive = [&](std::size_t k, Mesh&& mesh) {
    BodyCase& body = *bodies[k];
    body.definition.mesh = std::move(mesh);
    try {
      require_mesh_dimension(body, body.definition.mesh);
      check_boundary_names(body, body.definition);
    } catch (const InputError& error) {
      unusable[k] = error;
      return;
    }
    if (loaded) loaded(body_indices[k]);
  };
  try {
    read_gmsh_meshes(requests, receive, for_bodies(definition.meshing, body_indices));
  } catch (const InputError& error) {
    throw mesh_error(bodies, error);
  }
  for (const std::optional<InputError>& error : unusable) {
    if (error) throw *error;
  }
}

void load_meshes(CaseDefinition& definition) {
  load_meshes(definition, {});
}

std::string in_case_file(const std::filesystem::path& case_file, const std::string& message) {
  const std::string path = case_file.string();
  if (message.find(path) != std::string::npos) return message;
  return path + ": " + message;
}

}  // namespace robin
