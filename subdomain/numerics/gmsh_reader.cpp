#include "numerics/gmsh_reader.hpp"

#include <gmsh.h>

#include <Eigen/LU>
#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <map>
#include <mutex>
#include <random>
#include <set>
#include <sstream>
#include <system_error>
#include <unordered_map>

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>
#include <optional>

#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"

namespace robin {

namespace {

/// Gmsh is global state and not thread safe: one reader at a time.
std::mutex& gmsh_mutex() {
  static std::mutex mutex;
  return mutex;
}

/// Gmsh for one read. A .msh file is read by a Gmsh initialized once per process (under
/// gmsh_mutex) and cleared (gmsh::clear) before and after each read: Gmsh 4.8 leaks memory in
/// every initialize/finalize pair, more with every pair (a server reading a 800-triangle .msh
/// by SetupBody.mesh_path grew from 60 to 185 MiB over 2400 reads; benchmarks/soak_benchmark.py
/// --mesh-path). A .geo gets a fresh initialize/finalize pair: its script may set options that
/// must not carry over to the next read, and `-setnumber h SIZE` defines the .geo variable h
/// before any script is parsed. AbortOnError = 0 keeps Gmsh from throwing out of its parser
/// (which would leave the parser's state corrupt for later reads); errors are collected from
/// Gmsh's logger instead.
class GmshSession {
 public:
  GmshSession(bool script, double size) : kept_(!script) {
    if (kept_ && initialized_for_files()) {
      gmsh::clear();
    } else {
      end_kept_session();
      initialize(size);
      initialized_for_files() = kept_;
    }
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::option::setNumber("General.Verbosity", 1);
    gmsh::option::setNumber("General.AbortOnError", 0);
    gmsh::logger::start();
  }
  ~GmshSession() {
    gmsh::logger::stop();
    if (kept_) {
      gmsh::clear();
    } else {
      gmsh::finalize();
    }
  }
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  /// True while the Gmsh kept for .msh reads is initialized (in this process).
  static bool& initialized_for_files() {
    static bool initialized = false;
    return initialized;
  }
  static void end_kept_session() {
    if (!initialized_for_files()) return;
    gmsh::finalize();
    initialized_for_files() = false;
  }
  static void initialize(double size) {
    std::vector<std::string> arguments = {"robin"};
    if (size > 0.0) {
      std::ostringstream value;
      value.precision(17);
      value << size;
      arguments.insert(arguments.end(), {"-setnumber", "h", value.str()});
    }
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    gmsh::initialize(static_cast<int>(argv.size()), argv.data(), false);
  }

  bool kept_;
};

/// Builds error messages "<source>: <problem>", with Gmsh's mentions of the file read
/// replaced by the source name.
struct ErrorSource {
  std::string file;
  std::string name;
  InputError error(const std::string& problem) const {
    std::string text = problem;
    for (std::size_t at = text.find(file); !file.empty() && at != std::string::npos;
         at = text.find(file, at + name.size())) {
      text.replace(at, file.size(), name);
    }
    return InputError(name + ": " + text);
  }
};

/// The errors Gmsh logged during this session ("" when none), joined by "; ".
std::string gmsh_errors() {
  std::vector<std::string> log;
  gmsh::logger::get(log);
  const std::string prefix = "Error: ";
  std::string errors;
  for (const std::string& line : log) {
    if (line.rfind(prefix, 0) != 0) continue;
    errors += (errors.empty() ? "" : "; ") + line.substr(prefix.size());
  }
  if (errors.empty()) gmsh::logger::getLastError(errors);
  return errors;
}

/// Runs a Gmsh call; a Gmsh error (thrown or only logged) becomes an InputError.
template <typename Call>
void call_gmsh(const ErrorSource& source, const std::string& action, Call&& call) {
  try {
    call();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& exception) {
    throw source.error(action + " failed: " + exception.what());
  } catch (...) {
    const std::string error = gmsh_errors();
    throw source.error(action + " failed: " + (error.empty() ? "unknown Gmsh error" : error));
  }
  const std::string error = gmsh_errors();
  if (!error.empty()) throw source.error(action + " failed: " + error);
}

std::string gmsh_element_name(int gmsh_type) {
  std::string name;
  int dimension = 0, order = 0, node_count = 0, primary_count = 0;
  std::vector<double> coordinates;
  try {
    gmsh::model::mesh::getElementProperties(gmsh_type, name, dimension, order, node_count,
                                            coordinates, primary_count);
  } catch (...) {
    name = "unknown";
  }
  return name + " (Gmsh type " + std::to_string(gmsh_type) + ")";
}

/// Domain elements of one type: Gmsh node tags, and each element's tag and entity (the surface
/// in 2D, the volume in 3D).
struct GmshDomainBlock {
  std::vector<std::size_t> node_tags;
  std::vector<std::size_t> element_tags;
  std::vector<int> entities;
};

/// Domain elements and boundary facets with Gmsh node tags, before compaction.
struct GmshElements {
  std::map<ElementType, GmshDomainBlock> domain;
  std::map<std::string, std::pair<FacetType, std::vector<std::size_t>>> facets;
};

/// The model's dimension: 3 when it has a volume, 2 otherwise.
int model_dimension() {
  gmsh::vectorpair volumes;
  gmsh::model::getEntities(volumes, 3);
  return volumes.empty() ? 2 : 3;
}

/// The entities of dimension `dimension` whose elements form the body: those of its physical
/// groups of that dimension, or every such entity when there is no such group.
std::set<int> entities_to_read(int dimension) {
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, dimension);
  std::set<int> entities;
  if (groups.empty()) {
    gmsh::vectorpair all;
    gmsh::model::getEntities(all, dimension);
    for (const auto& [entity_dimension, tag] : all) entities.insert(tag);
    return entities;
  }
  for (const auto& [group_dimension, tag] : groups) {
    std::vector<int> members;
    gmsh::model::getEntitiesForPhysicalGroup(group_dimension, tag, members);
    entities.insert(members.begin(), members.end());
  }
  return entities;
}

/// The ElementType of a Gmsh element type of the body's dimension, if supported.
std::optional<ElementType> domain_element_type(int dimension, int gmsh_type) {
  static const std::map<int, ElementType> plane = {{2, ElementType::triangle3},
                                                   {9, ElementType::triangle6},
                                                   {3, ElementType::quadrilateral4}};
  static const std::map<int, ElementType> solid = {{4, ElementType::tetrahedron4},
                                                   {11, ElementType::tetrahedron10},
                                                   {5, ElementType::hexahedron8}};
  const std::map<int, ElementType>& known = dimension == 3 ? solid : plane;
  const auto found = known.find(gmsh_type);
  if (found == known.end()) return std::nullopt;
  return found->second;
}

/// The FacetType of a Gmsh element type of the boundary's dimension, if supported.
std::optional<FacetType> boundary_facet_type(int dimension, int gmsh_type) {
  static const std::map<int, FacetType> edges = {{1, FacetType::line2}, {8, FacetType::line3}};
  static const std::map<int, FacetType> faces = {{2, FacetType::triangle3},
                                                 {9, FacetType::triangle6},
                                                 {3, FacetType::quadrilateral4}};
  const std::map<int, FacetType>& known = dimension == 3 ? faces : edges;
  const auto found = known.find(gmsh_type);
  if (found == known.end()) return std::nullopt;
  return found->second;
}

void read_domain_elements(const ErrorSource& source, int dimension, GmshElements& elements) {
  for (const int entity : entities_to_read(dimension)) {
    std::vector<int> types;
    std::vector<std::vector<std::size_t>> element_tags, node_tags;
    gmsh::model::mesh::getElements(types, element_tags, node_tags, dimension, entity);
    for (std::size_t k = 0; k < types.size(); ++k) {
      const std::optional<ElementType> type = domain_element_type(dimension, types[k]);
      if (!type) {
        throw source.error(
            "unsupported " + std::to_string(dimension) + "D element " +
            gmsh_element_name(types[k]) +
            (dimension == 3 ? "; use 4-node or 10-node tetrahedra or 8-node hexahedra"
                            : "; use 3-node or 6-node triangles or 4-node quadrilaterals"));
      }
      GmshDomainBlock& block = elements.domain[*type];
      block.node_tags.insert(block.node_tags.end(), node_tags[k].begin(), node_tags[k].end());
      block.element_tags.insert(block.element_tags.end(), element_tags[k].begin(),
                                element_tags[k].end());
      block.entities.insert(block.entities.end(), element_tags[k].size(), entity);
    }
  }
  if (elements.domain.empty()) {
    throw source.error(dimension == 3
                           ? "contains no 3D elements (is the volume meshed, with a Physical "
                             "Volume?)"
                           : "contains no 2D elements (is the surface meshed, with a Physical "
                             "Surface?)");
  }
}

void read_boundary_facets(const ErrorSource& source, int dimension, GmshElements& elements) {
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups, dimension - 1);
  for (const auto& [group_dimension, group_tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(group_dimension, group_tag, name);
    if (name.empty()) name = std::to_string(group_tag);
    std::vector<int> members;
    gmsh::model::getEntitiesForPhysicalGroup(group_dimension, group_tag, members);
    for (const int member : members) {
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> element_tags, node_tags;
      gmsh::model::mesh::getElements(types, element_tags, node_tags, group_dimension, member);
      for (std::size_t k = 0; k < types.size(); ++k) {
        const std::optional<FacetType> type = boundary_facet_type(dimension, types[k]);
        if (!type) {
          throw source.error(
              "boundary '" + name + "': unsupported " + std::to_string(group_dimension) +
              "D element " + gmsh_element_name(types[k]) +
              (dimension == 3 ? "; use 3-node or 6-node triangles or 4-node quadrilaterals"
                              : "; use 2-node or 3-node lines"));
        }
        auto [entry, inserted] =
            elements.facets.try_emplace(name, *type, std::vector<std::size_t>{});
        if (entry->second.first != *type) {
          throw source.error("boundary '" + name + "' mixes " + to_string(entry->second.first) +
                             " and " + to_string(*type) + " facets");
        }
        entry->second.second.insert(entry->second.second.end(), node_tags[k].begin(),
                                    node_tags[k].end());
      }
    }
  }
}

/// Node tag -> compact index, for the nodes used by elements or edges, in ascending tag order.
std::unordered_map<std::size_t, int> compact_nodes(const GmshElements& elements) {
  std::vector<std::size_t> used;
  for (const auto& [type, block] : elements.domain) {
    used.insert(used.end(), block.node_tags.begin(), block.node_tags.end());
  }
  for (const auto& [name, facets] : elements.facets) {
    used.insert(used.end(), facets.second.begin(), facets.second.end());
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::unordered_map<std::size_t, int> index;
  for (std::size_t i = 0; i < used.size(); ++i) index.emplace(used[i], static_cast<int>(i));
  return index;
}

void fill_nodes(const ErrorSource& source, const std::unordered_map<std::size_t, int>& index,
                Mesh& mesh) {
  std::vector<std::size_t> tags;
  std::vector<double> coordinates, parametric;
  gmsh::model::mesh::getNodes(tags, coordinates, parametric, -1, -1, false, false);
  mesh.nodes.assign(index.size(), Eigen::Vector3d::Zero());
  mesh.node_tags.assign(index.size(), 0);
  double extent = 0.0;
  for (const double value : coordinates) extent = std::max(extent, std::abs(value));
  for (std::size_t k = 0; k < tags.size(); ++k) {
    const auto found = index.find(tags[k]);
    if (found == index.end()) continue;
    const double z = coordinates[3 * k + 2];
    if (mesh.dimension == 2 && std::abs(z) > 1e-10 * extent) {
      throw source.error("node " + std::to_string(tags[k]) + " has z = " + std::to_string(z) +
                         ": a mesh without volumes is a plane body and must lie in the z = 0 "
                         "plane");
    }
    mesh.nodes[found->second] = {coordinates[3 * k], coordinates[3 * k + 1],
                                 mesh.dimension == 2 ? 0.0 : z};
    mesh.node_tags[found->second] = tags[k];
  }
  for (std::size_t i = 0; i < mesh.node_tags.size(); ++i) {
    if (mesh.node_tags[i] == 0) throw source.error("an element uses a node that is not defined");
  }
}

std::vector<int> to_indices(const std::vector<std::size_t>& tags,
                            const std::unordered_map<std::size_t, int>& index) {
  std::vector<int> indices(tags.size());
  std::transform(tags.begin(), tags.end(), indices.begin(),
                 [&](std::size_t tag) { return index.at(tag); });
  return indices;
}

/// Twice the signed area of the element's corner polygon (positive when counter-clockwise).
double twice_signed_area(const Mesh& mesh, ElementType type, const int* nodes) {
  const int corners = type == ElementType::quadrilateral4 ? 4 : 3;
  double sum = 0.0;
  for (int i = 0; i < corners; ++i) {
    const Eigen::Vector3d& a = mesh.nodes[nodes[i]];
    const Eigen::Vector3d& b = mesh.nodes[nodes[(i + 1) % corners]];
    sum += a.x() * b.y() - b.x() * a.y();
  }
  return sum;
}

/// The element's signed measure: in 2D twice the signed area of its corner polygon (positive
/// when counter-clockwise), in 3D det(dx/dxi) at the reference centroid (positive when the
/// element has Gmsh's orientation).
double signed_measure(const Mesh& mesh, ElementType type, const int* nodes) {
  if (element_dimension(type) == 2) return twice_signed_area(mesh, type, nodes);
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  shape_functions(type, reference_centroid(type), values, gradients);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Zero();
  for (int i = 0; i < nodes_per_element(type); ++i) {
    jacobian += mesh.nodes[nodes[i]] * gradients.row(i);
  }
  return jacobian.determinant();
}

/// Orients every element positively (counter-clockwise in 2D, a positive Jacobian in 3D), entity
/// by entity: Gmsh meshes each surface or volume consistently, so the sign of the entity's total
/// signed measure gives its orientation, and a negatively oriented entity has every element
/// reversed. An element whose sign differs from its entity's is inverted (a folded or tangled
/// mesh) and refused, naming its tag.
void orient_positively(const ErrorSource& source, Mesh& mesh, ElementBlock& block,
                       const std::vector<int>& entities) {
  // Reverse the orientation: the corner order (midside nodes follow their edges); a
  // tetrahedron swaps corners 1 and 2, a hexahedron its faces' corner order.
  static const std::map<ElementType, std::vector<int>> reversed = {
      {ElementType::triangle3, {0, 2, 1}},
      {ElementType::triangle6, {0, 2, 1, 5, 4, 3}},
      {ElementType::quadrilateral4, {0, 3, 2, 1}},
      {ElementType::tetrahedron4, {0, 2, 1, 3}},
      {ElementType::tetrahedron10, {0, 2, 1, 3, 6, 5, 4, 7, 9, 8}},
      {ElementType::hexahedron8, {0, 3, 2, 1, 4, 7, 6, 5}}};
  const int count = nodes_per_element(block.type);
  std::map<int, double> entity_measure;
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    entity_measure[entities[e]] += signed_measure(mesh, block.type, &block.connectivity[e * count]);
  }
  const std::vector<int>& order = reversed.at(block.type);
  const bool solid = element_dimension(block.type) == 3;
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    int* nodes = &block.connectivity[e * count];
    const double measure = signed_measure(mesh, block.type, nodes);
    const double orientation = entity_measure[entities[e]] < 0.0 ? -1.0 : 1.0;
    if (measure * orientation <= 0.0) {
      throw source.error(block.element_label(e) + " (" + to_string(block.type) + " at node tag " +
                         std::to_string(mesh.node_tags[nodes[0]]) + ") " +
                         (measure == 0.0
                              ? (solid ? "has zero volume" : "has zero area")
                              : "is inverted against the other elements of " +
                                    std::string(solid ? "volume " : "surface ") +
                                    std::to_string(entities[e]) + " (a folded or tangled mesh)"));
    }
    if (orientation > 0.0) continue;
    const std::vector<int> original(nodes, nodes + count);
    for (int i = 0; i < count; ++i) nodes[i] = original[order[i]];
  }
}

Mesh extract_mesh(const ErrorSource& source) {
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  if (groups.empty()) {
    throw source.error(
        "defines no physical groups: add a Physical Surface for the body and Physical Curves for "
        "its boundaries (in 3D a Physical Volume and Physical Surfaces)");
  }
  const int dimension = model_dimension();
  GmshElements elements;
  read_domain_elements(source, dimension, elements);
  read_boundary_facets(source, dimension, elements);
  const std::unordered_map<std::size_t, int> index = compact_nodes(elements);
  Mesh mesh;
  mesh.dimension = dimension;
  fill_nodes(source, index, mesh);
  for (const auto& [type, domain] : elements.domain) {
    ElementBlock block{type, to_indices(domain.node_tags, index), domain.element_tags};
    orient_positively(source, mesh, block, domain.entities);
    mesh.blocks.push_back(std::move(block));
  }
  for (const auto& [name, facets] : elements.facets) {
    mesh.boundaries[name] = BoundaryGroup{facets.first, to_indices(facets.second, index)};
  }
  return mesh;
}

void check_options(const ErrorSource& source, const MeshReadOptions& options) {
  if (!std::isfinite(options.size) || options.size < 0.0) {
    throw source.error("mesh size " + std::to_string(options.size) + " is not >= 0");
  }
  if (options.element_order != 1 && options.element_order != 2) {
    throw source.error("element order " + std::to_string(options.element_order) + " is not 1 or 2");
  }
}

std::string lower_extension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

/// Reads (and, for a .geo, meshes) `path`.
Mesh read_mesh_file(const std::filesystem::path& path, const ErrorSource& source,
                    const MeshReadOptions& options) {
  check_options(source, options);
  const std::string extension = lower_extension(path);
  if (extension != ".msh" && extension != ".geo") {
    throw source.error("unsupported extension '" + extension + "': give a .msh or .geo file");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw source.error("the file does not exist or is not a regular file");
  }
  const std::lock_guard<std::mutex> lock(gmsh_mutex());
  const GmshSession session(extension == ".geo", options.size);
  call_gmsh(source, "reading", [&] { gmsh::open(path.string()); });
  if (extension == ".geo") {
    call_gmsh(source, "meshing", [&] {
      gmsh::option::setNumber("Mesh.ElementOrder", options.element_order);
      if (options.recombine) gmsh::option::setNumber("Mesh.RecombineAll", 1);
      gmsh::model::mesh::generate(model_dimension());
    });
  }
  Mesh mesh;
  call_gmsh(source, "extracting the mesh", [&] { mesh = extract_mesh(source); });
  return mesh;
}

/// Meshes the .geo `geo` in this (child) process and writes the mesh to `output` as binary
/// MSH 4.1 with every element, so that reading `output` gives the mesh that reading `geo`
/// gives. Throws InputError like read_mesh_file.
void mesh_to_file(const std::filesystem::path& geo, const MeshReadOptions& options,
                  const std::filesystem::path& output) {
  const ErrorSource source{"", "mesh file '" + geo.string() + "'"};
  check_options(source, options);
  const GmshSession session(true, options.size);
  call_gmsh(source, "reading", [&] { gmsh::open(geo.string()); });
  call_gmsh(source, "meshing", [&] {
    gmsh::option::setNumber("Mesh.ElementOrder", options.element_order);
    if (options.recombine) gmsh::option::setNumber("Mesh.RecombineAll", 1);
    gmsh::model::mesh::generate(model_dimension());
  });
  call_gmsh(source, "writing the mesh", [&] {
    gmsh::option::setNumber("Mesh.Binary", 1);
    gmsh::option::setNumber("Mesh.SaveAll", 1);
    gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
    gmsh::write(output.string());
  });
}

/// A .geo being meshed by a child process: its pid, the pipe that carries its error message
/// and the file it writes.
struct MeshingChild {
  pid_t pid = -1;
  int error_pipe = -1;
  std::filesystem::path output;
};

MeshingChild start_meshing_child(const MeshFileRequest& request,
                                 const std::filesystem::path& output) {
  int pipe_ends[2];
  if (pipe(pipe_ends) != 0) throw std::runtime_error("cannot create a pipe for meshing");
  const pid_t pid = fork();
  if (pid < 0) {
    close(pipe_ends[0]);
    close(pipe_ends[1]);
    throw std::runtime_error("cannot start a meshing process (fork failed)");
  }
  if (pid == 0) {
    close(pipe_ends[0]);
    std::string message;
    try {
      mesh_to_file(request.path, request.options, output);
      _exit(0);
    } catch (const std::exception& error) {
      message = error.what();
    } catch (...) {
      message = "mesh file '" + request.path.string() + "': meshing failed";
    }
    const ssize_t written = write(pipe_ends[1], message.data(), message.size());
    _exit(written >= 0 ? 1 : 2);
  }
  close(pipe_ends[1]);
  return {pid, pipe_ends[0], output};
}

/// Waits for `child`; returns its error message ("" when it succeeded).
std::string finish_meshing_child(const MeshingChild& child, const MeshFileRequest& request) {
  std::string message;
  char buffer[4096];
  for (ssize_t count; (count = read(child.error_pipe, buffer, sizeof buffer)) != 0;) {
    if (count < 0 && errno == EINTR) continue;
    if (count < 0) break;
    message.append(buffer, static_cast<std::size_t>(count));
  }
  close(child.error_pipe);
  int status = 0;
  while (waitpid(child.pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFEXITED(status) && WEXITSTATUS(status) == 0) return "";
  if (message.empty()) {
    message = "mesh file '" + request.path.string() + "': the meshing process " +
              (WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                   : "failed");
  }
  return message;
}

using Clock = std::chrono::steady_clock;

/// Blocks until one of the children `pending` (indices into `children`) has written to or
/// closed its error pipe (it is ending) and returns its index; the first on a poll error.
/// Calls `waiting` (when set) about once a second meanwhile.
std::size_t next_ended_child(const std::vector<std::optional<MeshingChild>>& children,
                             const std::vector<std::size_t>& pending,
                             const std::function<void()>& waiting) {
  std::vector<pollfd> pipes;
  for (const std::size_t k : pending) pipes.push_back({children[k]->error_pipe, POLLIN, 0});
  for (;;) {
    const int ready = poll(pipes.data(), pipes.size(), 1000);
    if (ready == 0) {
      if (waiting) waiting();
      continue;
    }
    if (ready < 0 && errno == EINTR) continue;
    if (ready < 0) return pending.front();
    for (std::size_t i = 0; i < pipes.size(); ++i) {
      if (pipes[i].revents != 0) return pending[i];
    }
  }
}

/// A private directory for the meshes of the children, removed on destruction.
class PrivateDirectory {
 public:
  PrivateDirectory() {
    std::string pattern = (std::filesystem::temp_directory_path() / "robin-mesh-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      throw std::runtime_error("cannot create a temporary directory for meshing in '" +
                               std::filesystem::temp_directory_path().string() + "'");
    }
    path_ = pattern;
  }
  ~PrivateDirectory() {
    std::error_code error;
    std::filesystem::remove_all(path_, error);
  }
  PrivateDirectory(const PrivateDirectory&) = delete;
  PrivateDirectory& operator=(const PrivateDirectory&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace

#if defined(__SANITIZE_ADDRESS__)
/// LeakSanitizer hook: Gmsh 4.8 itself leaks a few bytes per read (parser strings,
/// quadrilateral recombination); those leaks are not ours to fix. GCC's sanitizer runtime is a
/// shared library (libasan.so) that finds this hook through the dynamic symbol table: it stays
/// visible although the build hides our symbols (CMAKE_CXX_VISIBILITY_PRESET, CMakeLists.txt).
extern "C" __attribute__((visibility("default"))) const char* __lsan_default_suppressions() {
  return "leak:libgmsh.so\n";
}
#endif

Mesh read_gmsh_mesh(const std::filesystem::path& path, const MeshReadOptions& options) {
  const ErrorSource source{"", "mesh file '" + path.string() + "'"};
  Mesh mesh = read_mesh_file(path, source, options);
  mesh.source = path.string();
  return mesh;
}

std::vector<Mesh> read_gmsh_meshes(const std::vector<MeshFileRequest>& requests,
                                   const MeshReadObserver& observer) {
  std::vector<Mesh> meshes(requests.size());
  std::vector<std::optional<MeshingChild>> children(requests.size());
  std::vector<Clock::time_point> started(requests.size());
  const PrivateDirectory directory;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    if (lower_extension(requests[k].path) != ".geo") continue;
    const ErrorSource source{"", "mesh file '" + requests[k].path.string() + "'"};
    check_options(source, requests[k].options);
    std::error_code error;
    if (!std::filesystem::is_regular_file(requests[k].path, error)) {
      throw source.error("the file does not exist or is not a regular file");
    }
    children[k] =
        start_meshing_child(requests[k], directory.path() / ("body" + std::to_string(k) + ".msh"));
    started[k] = Clock::now();
    if (observer.started) observer.started(k);
  }
  std::string first_error;
  const auto read = [&](std::size_t k) {
    const std::filesystem::path& path = children[k] ? children[k]->output : requests[k].path;
    const ErrorSource source{path.string(), "mesh file '" + requests[k].path.string() + "'"};
    try {
      meshes[k] =
          read_mesh_file(path, source, children[k] ? MeshReadOptions{} : requests[k].options);
    } catch (const InputError& error) {
      if (first_error.empty()) first_error = error.what();
      return;
    }
    meshes[k].source = requests[k].path.string();
    if (observer.finished) {
      observer.finished(k, meshes[k],
                        std::chrono::duration<double>(Clock::now() - started[k]).count());
    }
  };
  // each child's mesh is read as soon as it ends, in the order they end
  std::vector<std::size_t> pending;
  for (std::size_t k = 0; k < requests.size(); ++k) {
    if (children[k]) pending.push_back(k);
  }
  while (!pending.empty()) {
    const std::size_t k = next_ended_child(children, pending, observer.waiting);
    pending.erase(std::find(pending.begin(), pending.end(), k));
    const std::string error = finish_meshing_child(*children[k], requests[k]);
    if (!error.empty() && first_error.empty()) first_error = error;
    if (error.empty() && first_error.empty()) read(k);
  }
  for (std::size_t k = 0; k < requests.size() && first_error.empty(); ++k) {
    if (children[k]) continue;
    started[k] = Clock::now();
    if (observer.started) observer.started(k);
    read(k);
  }
  if (!first_error.empty()) throw InputError(first_error);
  return meshes;
}

namespace {

/// The script's text without comments (// to the end of the line, /* ... */) and without the
/// contents of double-quoted strings; a string's own text is returned in `strings`.
std::string code_of_geo_script(const std::string& text, std::vector<std::string>& strings) {
  std::string code;
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (text.compare(k, 2, "//") == 0) {
      k = text.find('\n', k);
      if (k == std::string::npos) break;
      code += '\n';
    } else if (text.compare(k, 2, "/*") == 0) {
      k = text.find("*/", k + 2);
      if (k == std::string::npos) break;
      ++k;
      code += ' ';
    } else if (text[k] == '"') {
      std::string value;
      for (++k; k < text.size() && text[k] != '"'; ++k) {
        if (text[k] == '\\' && k + 1 < text.size()) ++k;
        value += text[k];
      }
      strings.push_back(value);
      code += "\"\"";
    } else {
      code += text[k];
    }
  }
  return code;
}

bool is_identifier_character(char character) {
  return std::isalnum(static_cast<unsigned char>(character)) != 0 || character == '_';
}

bool mentions_identifier(const std::string& code, const std::string& name) {
  for (std::size_t at = code.find(name); at != std::string::npos; at = code.find(name, at + 1)) {
    const bool starts = at == 0 || !is_identifier_character(code[at - 1]);
    const std::size_t end = at + name.size();
    const bool ends = end >= code.size() || !is_identifier_character(code[end]);
    if (starts && ends) return true;
  }
  return false;
}

}  // namespace

GeoVariableUse geo_variable_use(const std::filesystem::path& path, const std::string& name) {
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError("mesh file '" + path.string() + "' cannot be read");
  std::ostringstream text;
  text << file.rdbuf();
  std::vector<std::string> strings;
  const std::string code = code_of_geo_script(text.str(), strings);
  if (mentions_identifier(code, name)) return GeoVariableUse::used;
  return mentions_identifier(code, "Include") ? GeoVariableUse::indeterminate
                                              : GeoVariableUse::unused;
}

}  // namespace robin
