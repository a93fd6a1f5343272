#include "server/setup_decoding.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>

#include "mesh_codec.hpp"
#include "numerics/errors.hpp"
#include "numerics/mesh_validity.hpp"
#include "numerics/msh_file.hpp"
#include "server/file_access.hpp"
#include "server/mesh_file_reader.hpp"

namespace robin {
namespace {

/// "body 'NAME': " (or "SetupBody: " before the name is known), the prefix of every message.
std::string body_context(const std::string& name) {
  return "body '" + name + "'";
}

[[noreturn]] void fail(const std::string& context, const std::string& field,
                       const std::string& problem) {
  throw InputError(context + ": SetupBody." + field + " " + problem);
}

std::string format_value(double value) {
  std::ostringstream stream;
  stream.precision(12);
  stream << value;
  return stream.str();
}

std::string decode_body_name(const std::string& name) {
  if (name.size() > maximum_body_name_length) {
    throw InputError("SetupBody.body_name has " + std::to_string(name.size()) +
                     " characters: at most 64 (letters, digits, '_' and '-')");
  }
  const bool valid = !name.empty() && std::all_of(name.begin(), name.end(), [](unsigned char c) {
    return std::isalnum(c) != 0 || c == '_' || c == '-';
  });
  if (!valid) {
    throw InputError("SetupBody.body_name '" + name +
                     "' is not a valid body name (letters, digits, '_' and '-', not empty)");
  }
  return name;
}

/// Whether `path` names an MSH file (.msh, any case), which the server reads itself.
bool is_msh_file(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension == ".msh";
}

/// The mesh from `mesh` (MeshData) or, when absent, `mesh_path` under the data directory (not
/// read when larger than the limit). A .msh file is read in this process by the native reader,
/// whose allocations are bounded by the file's size (msh_file.hpp); a .geo file is meshed by
/// Gmsh in robin-mesh-reader, a child process with a memory cap (read_mesh_file_in_child). A reader
/// error is rethrown with the body and field prepended. Nothing received is run: a MeshData is
/// data, and a mesh_path names a file the server's operator put in the data directory.
Mesh decode_body_mesh(const protocol::SetupBody& message, const std::string& context,
                      const MeshFiles& files) {
  if (message.has_mesh()) return decode_mesh(message.mesh(), context);
  if (message.mesh_path().empty()) {
    fail(context, "mesh", "and SetupBody.mesh_path are both absent: send the mesh as MeshData");
  }
  const std::string field = context + ": SetupBody.mesh_path";
  const std::filesystem::path path =
      resolve_data_file(files.data_directory, message.mesh_path(), field);
  check_data_file_size(path, message.mesh_path(), files.maximum_bytes, field);
  try {
    Mesh mesh = is_msh_file(path) ? read_msh_file(path, message.mesh_path())
                                  : read_mesh_file_in_child(path, files.reader);
    check_element_validity(mesh, context + ": SetupBody.mesh_path");
    return mesh;
  } catch (const InputError& error) {
    throw InputError(context + ": SetupBody.mesh_path: " + error.what());
  }
}

PlaneModel decode_model(const protocol::SetupBody& message, const std::string& context) {
  switch (message.model()) {
    case protocol::PLANE_STRAIN:
      return PlaneModel::plane_strain;
    case protocol::PLANE_STRESS:
      return PlaneModel::plane_stress;
    default:
      fail(context, "model", "is unspecified: give PLANE_STRAIN or PLANE_STRESS");
  }
}

/// The material of a body of `dimension` 2 (a plane model must be given; 9 Voigt values) or 3
/// (the model is ignored; 36 Voigt values, or an isotropic solid).
Material decode_material(const protocol::SetupBody& message, const std::string& context,
                         int dimension) {
  const PlaneModel model =
      dimension == 2 ? decode_model(message, context) : PlaneModel::plane_strain;
  const std::string material_context = context + ": SetupBody material";
  if (message.voigt_size() == 0) {
    if (dimension == 3) {
      return make_isotropic_solid_material(message.young_modulus(), message.poisson_ratio(),
                                           material_context);
    }
    return make_isotropic_material(message.young_modulus(), message.poisson_ratio(), model,
                                   material_context);
  }
  if (message.young_modulus() != 0.0 || message.poisson_ratio() != 0.0) {
    fail(context, "voigt", "is given together with young_modulus/poisson_ratio: give one of them");
  }
  const int size = dimension == 3 ? 6 : 3;
  if (message.voigt_size() != size * size) {
    const std::string shape = std::to_string(size) + "x" + std::to_string(size);
    fail(context, "voigt",
         "has " + std::to_string(message.voigt_size()) + " values, expected " +
             std::to_string(size * size) + " (row-major " + shape +
             (dimension == 3 ? ", a solid body" : "") + ")");
  }
  Eigen::MatrixXd stiffness(size, size);
  for (int row = 0; row < size; ++row) {
    for (int column = 0; column < size; ++column)
      stiffness(row, column) = message.voigt(size * row + column);
  }
  return make_voigt_material(stiffness, model, material_context);
}

/// A vector of `dimension` finite values from a repeated field (`field` names it in messages);
/// z = 0 in 2D.
Eigen::Vector3d decode_vector(const google::protobuf::RepeatedField<double>& values, int dimension,
                              const std::string& context, const std::string& field) {
  if (values.size() != dimension) {
    fail(context, field,
         "has " + std::to_string(values.size()) + " values, expected " +
             (dimension == 2 ? std::string("2 (x, y)") : std::string("3 (x, y, z)")));
  }
  Eigen::Vector3d vector = Eigen::Vector3d::Zero();
  for (int component = 0; component < dimension; ++component) vector[component] = values[component];
  if (!vector.allFinite()) fail(context, field, "has a value that is not a finite number");
  return vector;
}

/// Checks that `name` is a boundary (physical curve) of `mesh`.
void check_boundary(const Mesh& mesh, const std::string& name, const std::string& context,
                    const std::string& field) {
  if (name.empty()) fail(context, field, "is empty: give the name of a physical curve");
  if (mesh.boundaries.count(name) != 0) return;
  std::string known;
  for (const auto& [boundary_name, group] : mesh.boundaries) {
    known += (known.empty() ? "" : ", ") + boundary_name;
  }
  fail(context, field,
       "'" + name + "' is not a boundary of the mesh (its boundaries: " +
           (known.empty() ? "none" : known) + ")");
}

DirichletCondition decode_dirichlet(const protocol::Dirichlet& message, const Mesh& mesh,
                                    const std::string& context, const std::string& field) {
  check_boundary(mesh, message.boundary(), context, field + ".boundary");
  if (mesh.dimension == 2) {
    if (message.has_z()) fail(context, field + ".z", "is given: a plane problem has no u_z");
    if (!message.has_x() && !message.has_y()) {
      fail(context, field, "prescribes neither x nor y: give at least one");
    }
  } else if (!message.has_x() && !message.has_y() && !message.has_z()) {
    fail(context, field, "prescribes none of x, y and z: give at least one");
  }
  DirichletCondition condition{message.boundary(), std::nullopt, std::nullopt, std::nullopt};
  if (message.has_x()) condition.x = message.x();
  if (message.has_y()) condition.y = message.y();
  if (message.has_z()) condition.z = message.z();
  for (const std::optional<double>& value : {condition.x, condition.y, condition.z}) {
    if (value && !std::isfinite(*value)) {
      fail(context, field, "has a value that is not a finite number");
    }
  }
  return condition;
}

TractionCondition decode_traction(const protocol::Traction& message, const Mesh& mesh,
                                  const std::string& context, const std::string& field) {
  check_boundary(mesh, message.boundary(), context, field + ".boundary");
  TractionCondition condition;
  condition.boundary = message.boundary();
  condition.is_pressure = message.is_pressure();
  if (!message.is_pressure()) {
    condition.vector = decode_vector(message.vector(), mesh.dimension, context, field + ".vector");
    return condition;
  }
  if (message.vector_size() != 0) {
    fail(context, field + ".vector", "is given with is_pressure = true: give one of them");
  }
  if (!std::isfinite(message.pressure())) {
    fail(context, field + ".pressure", "is not a finite number");
  }
  condition.pressure = message.pressure();
  return condition;
}

InterfaceOperatorKind decode_interface_operator(const std::string& name,
                                                const std::string& context) {
  if (name.empty() || name == "auto") return InterfaceOperatorKind::automatic;
  if (name == "dense") return InterfaceOperatorKind::dense;
  if (name == "factor") return InterfaceOperatorKind::factor;
  fail(context, "solver.interface_operator",
       "is '" + name + "', expected \"auto\", \"dense\" or \"factor\"");
}

LinearSolverKind decode_linear_solver(const std::string& name, const std::string& context) {
  if (name.empty() || name == "direct") return LinearSolverKind::direct;
  if (name == "multigrid") return LinearSolverKind::multigrid;
  fail(context, "solver.linear_solver", "is '" + name + "', expected \"direct\" or \"multigrid\"");
}

void decode_solver(const protocol::SolverSettings& message, const std::string& context,
                   DecodedSetup& setup) {
  const double tolerance = message.qp_tolerance();
  if (!std::isfinite(tolerance) || tolerance < 0.0) {
    fail(context, "solver.qp_tolerance",
         "is " + format_value(tolerance) + ", expected > 0 (or 0 for the default)");
  }
  if (tolerance > 0.0) setup.qp.relative_tolerance = tolerance;
  if (message.qp_max_iterations() > 0) {
    if (message.qp_max_iterations() > static_cast<unsigned>(std::numeric_limits<int>::max())) {
      fail(context, "solver.qp_max_iterations", "is too large");
    }
    setup.qp.max_iterations = static_cast<int>(message.qp_max_iterations());
  }
  setup.body.interface_operator = decode_interface_operator(message.interface_operator(), context);
  if (message.dense_limit() > 0) {
    if (message.dense_limit() > static_cast<unsigned>(std::numeric_limits<int>::max())) {
      fail(context, "solver.dense_limit", "is too large");
    }
    setup.body.dense_limit = static_cast<int>(message.dense_limit());
  }
  setup.body.linear_solver = decode_linear_solver(message.linear_solver(), context);
}

/// SetupBody.contact_boundaries: 1 to maximum_contact_boundaries names, each a boundary of the
/// mesh, none repeated (as the Python server checks them).
std::vector<std::string> decode_contact_boundaries(const protocol::SetupBody& message,
                                                   const Mesh& mesh, const std::string& context) {
  const int count = message.contact_boundaries_size();
  if (count == 0) {
    fail(context, "contact_boundaries",
         "is empty: name at least one boundary that may touch another body");
  }
  if (count > maximum_contact_boundaries) {
    fail(context, "contact_boundaries",
         "has " + std::to_string(count) + " names, more than the " +
             std::to_string(maximum_contact_boundaries) + " contact boundaries a body may have");
  }
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const std::string& name = message.contact_boundaries(k);
    const std::string field = "contact_boundaries[" + std::to_string(k) + "]";
    check_boundary(mesh, name, context, field);
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      fail(context, field, "repeats '" + name + "'");
    }
    names.push_back(name);
  }
  return names;
}

}  // namespace

DecodedSetup decode_setup_body(const protocol::SetupBody& message, const MeshFiles& files) {
  DecodedSetup setup;
  BodyDefinition& definition = setup.definition;
  definition.name = decode_body_name(message.body_name());
  const std::string context = body_context(definition.name);
  // The material and the body force depend on the body's dimension, which MeshData states
  // (dimension 3: a solid body) and a mesh file only once read. They are decoded here, before
  // the mesh (so a plane body's errors come in the order of protocol 2.3), for a body whose
  // dimension is known or that looks plane, and after the mesh otherwise or when the file's
  // mesh turns out solid.
  const bool from_file = !message.has_mesh() && !message.mesh_path().empty();
  const int stated_dimension = message.has_mesh() && message.mesh().dimension() == 3 ? 3 : 2;
  const bool looks_solid = message.voigt_size() == 36 || message.body_force_size() == 3 ||
                           message.model() == protocol::PLANE_MODEL_UNSPECIFIED;
  const bool decode_early = !from_file || !looks_solid;
  const auto decode_loads = [&](int dimension) {
    definition.material = decode_material(message, context, dimension);
    definition.body_force = Eigen::Vector3d::Zero();
    if (message.body_force_size() != 0) {
      definition.body_force = decode_vector(message.body_force(), dimension, context, "body_force");
    }
  };
  if (decode_early) decode_loads(stated_dimension);
  decode_solver(message.solver(), context, setup);
  setup.body.rigid_motions =
      message.floating() ? RigidMotions::held_by_contact : RigidMotions::refuse;
  definition.mesh = decode_body_mesh(message, context, files);
  if (!decode_early || definition.mesh.dimension != stated_dimension) {
    decode_loads(definition.mesh.dimension);
  }
  definition.contact_boundaries = decode_contact_boundaries(message, definition.mesh, context);
  for (int k = 0; k < message.dirichlet_size(); ++k) {
    definition.dirichlet.push_back(decode_dirichlet(message.dirichlet(k), definition.mesh, context,
                                                    "dirichlet[" + std::to_string(k) + "]"));
  }
  for (int k = 0; k < message.traction_size(); ++k) {
    definition.tractions.push_back(decode_traction(message.traction(k), definition.mesh, context,
                                                   "traction[" + std::to_string(k) + "]"));
  }
  return setup;
}

}  // namespace robin
