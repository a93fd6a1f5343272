// The reference against which tests/unit/msh_file_test.cpp checks the native MSH reader: a .msh
// file read through Gmsh's own C++ API and turned into a Mesh by the code robin used before the
// native reader (gmsh_reader.cpp until 2026-11-27), kept here unchanged in substance, but for the
// orientation of the elements: both readers call orient_elements_positively (msh_file.hpp), so
// the comparison checks what each reader extracts. Test code only: it links libgmsh.

#include "gmsh_api_reader.hpp"

#include <gmsh.h>

#include <algorithm>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <unordered_map>

#include "numerics/errors.hpp"
#include "numerics/msh_file.hpp"

namespace robin {

namespace {

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
  static const std::map<int, ElementType> plane = {
      {2, ElementType::triangle3}, {9, ElementType::triangle6}, {3, ElementType::quadrilateral4}};
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
  static const std::map<int, FacetType> faces = {
      {2, FacetType::triangle3}, {9, FacetType::triangle6}, {3, FacetType::quadrilateral4}};
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
        throw source.error("unsupported " + std::to_string(dimension) + "D element " +
                           gmsh_element_name(types[k]) +
                           (dimension == 3
                                ? "; use 4-node or 10-node tetrahedra or 8-node hexahedra"
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
    orient_elements_positively(source.name, mesh, block, domain.entities);
    mesh.blocks.push_back(std::move(block));
  }
  for (const auto& [name, facets] : elements.facets) {
    mesh.boundaries[name] = BoundaryGroup{facets.first, to_indices(facets.second, index)};
  }
  return mesh;
}

bool& gmsh_initialized() {
  static bool initialized = false;
  return initialized;
}

/// Gmsh kept initialized between reads (a fresh initialize/finalize pair per read leaks more
/// with every pair), cleared before each read; a .geo gets a fresh pair with `arguments`.
void start_gmsh(std::vector<std::string> arguments = {}) {
  if (gmsh_initialized() && !arguments.empty()) {
    gmsh::finalize();
    gmsh_initialized() = false;
  }
  if (!gmsh_initialized()) {
    arguments.insert(arguments.begin(), "robin");
    std::vector<char*> argv;
    for (std::string& argument : arguments) argv.push_back(argument.data());
    gmsh::initialize(static_cast<int>(argv.size()), argv.data(), false);
    gmsh_initialized() = true;
  }
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::clear();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::option::setNumber("General.Verbosity", 1);
  gmsh::option::setNumber("General.AbortOnError", 0);
  gmsh::logger::start();
}

}  // namespace

Mesh read_msh_with_gmsh_api(const std::filesystem::path& path) {
  const ErrorSource source{"", "mesh file '" + path.string() + "'"};
  start_gmsh();
  Mesh mesh;
  try {
    call_gmsh(source, "reading", [&] { gmsh::open(path.string()); });
    call_gmsh(source, "extracting the mesh", [&] { mesh = extract_mesh(source); });
  } catch (...) {
    gmsh::logger::stop();
    throw;
  }
  gmsh::logger::stop();
  mesh.source = path.string();
  return mesh;
}

void write_msh_with_gmsh_api(const std::filesystem::path& geo, const MeshReadOptions& options,
                             const std::vector<MshWriting>& writings) {
  const ErrorSource source{"", "mesh file '" + geo.string() + "'"};
  std::vector<std::string> arguments = {"-setnumber", "h", "0"};
  if (options.size > 0.0) {
    std::ostringstream value;
    value.precision(17);
    value << options.size;
    arguments[2] = value.str();
  } else {
    arguments.clear();
  }
  start_gmsh(arguments.empty() ? std::vector<std::string>{"-v", "1"} : arguments);
  call_gmsh(source, "reading", [&] { gmsh::open(geo.string()); });
  call_gmsh(source, "meshing", [&] {
    gmsh::option::setNumber("Mesh.ElementOrder", options.element_order);
    gmsh::option::setNumber("Mesh.RecombineAll", options.recombine ? 1 : 0);
    gmsh::model::mesh::generate(model_dimension());
  });
  for (const MshWriting& writing : writings) {
    call_gmsh(source, "writing", [&] {
      gmsh::option::setNumber("Mesh.Binary", writing.binary ? 1 : 0);
      gmsh::option::setNumber("Mesh.SaveAll", writing.save_all ? 1 : 0);
      gmsh::option::setNumber("Mesh.MshFileVersion", writing.version);
      gmsh::write(writing.path.string());
    });
  }
  gmsh::logger::stop();
  gmsh::finalize();
  gmsh_initialized() = false;
}

}  // namespace robin
