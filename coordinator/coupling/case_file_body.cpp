#include "coupling/case_file_body.hpp"

#include <algorithm>
#include <cctype>
#include <sstream>

#include "numerics/errors.hpp"
#include "numerics/gmsh_reader.hpp"

namespace robin {

namespace {

const std::vector<std::string> body_keys{"name",       "mesh",      "mesh_size", "element_order",
                                         "recombine",  "model",     "material",  "contact_boundary",
                                         "body_force", "dirichlet", "traction",  "floating"};
const std::vector<std::string> material_keys{"young", "poisson", "voigt"};
const std::vector<std::string> dirichlet_keys{"boundary", "x", "y", "z", "fix"};
const std::vector<std::string> traction_keys{"boundary", "vector", "pressure"};

bool is_valid_body_name(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_' || c == '-';
  });
}

/// "FILE:LINE" of `key` in `table`, without the body part.
std::string file_location(const CheckedTable& table, std::string_view key) {
  CaseContext context = table.context();
  context.body.clear();
  return context.prefix(table.line(key));
}

/// A non-empty boundary name, recorded for the check against the mesh in load_body.
std::string read_boundary_name(const CheckedTable& table, std::string_view key,
                               std::vector<BoundaryReference>& references) {
  std::string name = table.string(key);
  if (name.empty()) table.fail(key, "the boundary name is empty");
  references.push_back({name, table.field(key), file_location(table, key)});
  return name;
}

std::string lowercase(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

void read_mesh(const CheckedTable& table, const std::filesystem::path& directory, BodyCase& body) {
  const std::string mesh = table.string("mesh");
  if (mesh.empty()) table.fail("mesh", "the mesh file name is empty");
  body.mesh_context = table.context().prefix(table.line("mesh")) + ": " + table.field("mesh");
  std::filesystem::path path(mesh);
  if (path.is_relative()) path = directory / path;
  body.mesh_path = std::filesystem::absolute(path).lexically_normal();
  const std::string extension = lowercase(body.mesh_path.extension().string());
  if (extension != ".msh" && extension != ".geo") {
    table.fail("mesh", "'" + mesh + "' is neither a .msh nor a .geo file");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(body.mesh_path, error)) {
    table.fail("mesh", "mesh file '" + body.mesh_path.string() + "' does not exist");
  }
  for (const char* key : {"mesh_size", "element_order", "recombine"}) {
    if (extension == ".msh" && table.contains(key)) {
      table.fail(key, "applies only to a .geo mesh; '" + mesh + "' is already meshed");
    }
  }
  if (auto size = table.optional_number("mesh_size")) {
    if (*size <= 0.0) table.fail("mesh_size", "must be > 0, got " + format_number(*size));
    body.mesh_options.size = *size;
    // mesh_size defines the .geo variable h: a script without h would silently ignore it
    if (geo_variable_use(body.mesh_path, "h") == GeoVariableUse::unused) {
      table.fail("mesh_size",
                 "has no effect: '" + mesh +
                     "' never uses the variable h, which mesh_size sets. Give its points the "
                     "size h (e.g. 'DefineConstant[ h = 0.1 ];' and 'Point(1) = {0, 0, 0, h};') "
                     "or remove mesh_size");
    }
  }
  if (auto order = table.optional_integer("element_order")) {
    if (*order != 1 && *order != 2) {
      table.fail("element_order", "must be 1 or 2, got " + std::to_string(*order));
    }
    body.mesh_options.element_order = *order;
  }
  body.mesh_options.recombine = table.optional_boolean("recombine").value_or(false);
  if (body.mesh_options.recombine && body.mesh_options.element_order == 2) {
    // Mesh (numerics/mesh.hpp) has no quadratic quadrilaterals.
    table.fail("recombine",
               "recombine = true with element_order = 2 gives quadratic quadrilaterals, which are "
               "not supported: use element_order = 1 or recombine = false");
  }
}

/// A plane vector [x, y] as the point (x, y, 0); a solid one [x, y, z] as it is.
Eigen::Vector3d spatial(const Eigen::VectorXd& vector) {
  return {vector[0], vector[1], vector.size() == 3 ? vector[2] : 0.0};
}

/// young + poisson, or voigt (3 x 3 for a plane body, 6 x 6 for a solid one); the material
/// functions check the values. `model` is empty for a solid body.
Material read_material(const CheckedTable& body, std::optional<PlaneModel> model) {
  const CheckedTable table = body.table("material", material_keys);
  const bool has_young = table.contains("young");
  const bool has_poisson = table.contains("poisson");
  const bool has_voigt = table.contains("voigt");
  if (has_voigt && (has_young || has_poisson)) {
    table.fail(has_young ? "young" : "poisson",
               "give either young and poisson, or voigt, not both");
  }
  if (!has_voigt && !has_young && !has_poisson) {
    table.fail("", std::string("give either young and poisson (isotropic), or voigt (") +
                       (model ? "3x3" : "6x6") + " stiffness)");
  }
  const std::string context = table.context().prefix(table.line()) + ": material";
  if (has_voigt) {
    const Eigen::MatrixXd voigt = *table.optional_matrix("voigt", model ? 3 : 6);
    return make_voigt_material(voigt, model.value_or(PlaneModel::plane_strain), context);
  }
  if (!has_poisson) table.fail("poisson", "missing: young needs poisson");
  if (!has_young) table.fail("young", "missing: poisson needs young");
  const double young = table.number("young");
  const double poisson = table.number("poisson");
  if (!model) return make_isotropic_solid_material(young, poisson, context);
  return make_isotropic_material(young, poisson, *model, context);
}

/// The components a [[body.dirichlet]] table may prescribe: x and y, and z in a solid body.
std::vector<std::string> displacement_components(int dimension) {
  if (dimension == 3) return {"x", "y", "z"};
  return {"x", "y"};
}

std::optional<double>& component_of(DirichletCondition& condition, const std::string& component) {
  if (component == "x") return condition.x;
  if (component == "y") return condition.y;
  return condition.z;
}

/// fix = "both" (plane) or "all" (solid) fixes every component, fix = "x" | "y" | "z" one.
void read_fixed_components(const CheckedTable& table, int dimension,
                           DirichletCondition& condition) {
  const std::string every = dimension == 3 ? "all" : "both";
  std::vector<std::string> choices = displacement_components(dimension);
  choices.insert(choices.begin(), every);
  const auto fix = table.optional_choice("fix", choices);
  if (!fix) return;
  for (const std::string& component : displacement_components(dimension)) {
    if (*fix != every && *fix != component) continue;
    std::optional<double>& value = component_of(condition, component);
    if (value) {
      table.fail("fix", "fix = \"" + *fix + "\" sets u_" + component +
                            " = 0 and cannot be combined with " + component + " = " +
                            format_number(*value));
    }
    value = 0.0;
  }
}

DirichletCondition read_dirichlet(const CheckedTable& table, int dimension,
                                  std::vector<BoundaryReference>& references) {
  DirichletCondition condition;
  condition.boundary = read_boundary_name(table, "boundary", references);
  condition.x = table.optional_number("x");
  condition.y = table.optional_number("y");
  if (table.contains("z") && dimension != 3) {
    table.fail("z", "u_z applies to solid bodies only (a case file with dimension = 3)");
  }
  condition.z = table.optional_number("z");
  read_fixed_components(table, dimension, condition);
  if (!condition.x && !condition.y && !condition.z) {
    table.fail("", dimension == 3 ? "prescribes nothing: give x, y and/or z, or fix = \"all\" | "
                                    "\"x\" | \"y\" | \"z\""
                                  : "prescribes nothing: give x and/or y, or fix = \"both\" | "
                                    "\"x\" | \"y\"");
  }
  return condition;
}

TractionCondition read_traction(const CheckedTable& table, int dimension,
                                std::vector<BoundaryReference>& references) {
  TractionCondition condition;
  condition.boundary = read_boundary_name(table, "boundary", references);
  const auto vector = table.optional_vector("vector", dimension);
  const auto pressure = table.optional_number("pressure");
  if (vector && pressure) table.fail("pressure", "give either vector or pressure, not both");
  if (!vector && !pressure) {
    table.fail("", dimension == 3 ? "give either vector = [tx, ty, tz] or pressure = p"
                                  : "give either vector = [tx, ty] or pressure = p");
  }
  condition.is_pressure = pressure.has_value();
  if (vector) condition.vector = spatial(*vector);
  if (pressure) condition.pressure = *pressure;
  return condition;
}

/// The plane model of a plane body (required); none for a solid body (refused).
std::optional<PlaneModel> read_model(const CheckedTable& table, int dimension) {
  if (dimension == 3) {
    if (table.contains("model")) {
      table.fail("model",
                 "a solid body (dimension = 3) has no plane model; remove model, or set "
                 "dimension = 2 for plane bodies");
    }
    return std::nullopt;
  }
  const auto model = table.optional_choice("model", {"plane_strain", "plane_stress"});
  if (!model) table.fail("model", "missing required key (\"plane_strain\" or \"plane_stress\")");
  return *model == "plane_strain" ? PlaneModel::plane_strain : PlaneModel::plane_stress;
}

}  // namespace

std::string format_number(double value) {
  std::ostringstream text;
  text.precision(12);
  text << value;
  return text.str();
}

BodyCase read_body_case(const TableEntry& entry, const CaseContext& file,
                        const std::filesystem::path& directory, ContactBoundaryKey contact_key,
                        int dimension) {
  // The name goes into every later message, so it is looked at before the keys are checked.
  const auto name_node = (*entry.table)["name"].value<std::string>();
  CaseContext context = file;
  context.body = name_node.value_or("");
  const CheckedTable table(*entry.table, entry.path, context, body_keys);
  BodyCase body;
  BodyDefinition& definition = body.definition;
  definition.name = table.string("name");
  if (!is_valid_body_name(definition.name)) {
    table.fail("name", "'" + definition.name +
                           "' is not a valid body name (letters, digits, '_' and '-' only)");
  }
  body.context = file.file + ": body '" + definition.name + "'";
  body.dimension = dimension;
  read_mesh(table, directory, body);
  const std::optional<PlaneModel> model = read_model(table, dimension);
  if (contact_key == ContactBoundaryKey::required) {
    definition.contact_boundaries = {
        read_boundary_name(table, "contact_boundary", body.boundary_references)};
  } else if (table.contains("contact_boundary")) {
    table.fail("contact_boundary",
               "the case has [[interface]] tables: give the contact boundaries there "
               "(interface.boundaries)");
  }
  if (const auto body_force = table.optional_vector("body_force", dimension)) {
    definition.body_force = spatial(*body_force);
  }
  body.floating = table.optional_boolean("floating").value_or(false);
  definition.material = read_material(table, model);
  for (const TableEntry& item : table.array_of_tables("dirichlet")) {
    const CheckedTable condition(*item.table, item.path, context, dirichlet_keys);
    definition.dirichlet.push_back(read_dirichlet(condition, dimension, body.boundary_references));
  }
  for (const TableEntry& item : table.array_of_tables("traction")) {
    const CheckedTable condition(*item.table, item.path, context, traction_keys);
    definition.tractions.push_back(read_traction(condition, dimension, body.boundary_references));
  }
  return body;
}

}  // namespace robin
