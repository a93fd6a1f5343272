#include "numerics/mesh.hpp"

#include <algorithm>
#include <stdexcept>

#include "numerics/errors.hpp"

namespace robin {

int nodes_per_element(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return 3;
    case ElementType::triangle6:
      return 6;
    case ElementType::quadrilateral4:
      return 4;
  }
  throw std::invalid_argument("nodes_per_element: unknown element type");
}

int nodes_per_edge(EdgeType type) {
  switch (type) {
    case EdgeType::line2:
      return 2;
    case EdgeType::line3:
      return 3;
  }
  throw std::invalid_argument("nodes_per_edge: unknown edge type");
}

std::string to_string(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return "triangle3";
    case ElementType::triangle6:
      return "triangle6";
    case ElementType::quadrilateral4:
      return "quadrilateral4";
  }
  throw std::invalid_argument("to_string: unknown element type");
}

std::string ElementBlock::element_label(std::size_t element) const {
  if (element < tags.size()) return "element tag " + std::to_string(tags[element]);
  return "element " + std::to_string(element + 1) + " of the " + to_string(type) + " block";
}

std::vector<int> BoundaryGroup::nodes() const {
  std::vector<int> distinct = connectivity;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  return distinct;
}

std::size_t Mesh::element_count() const {
  std::size_t count = 0;
  for (const ElementBlock& block : blocks) count += block.element_count();
  return count;
}

const BoundaryGroup& Mesh::boundary(const std::string& name) const {
  const auto found = boundaries.find(name);
  if (found != boundaries.end()) return found->second;
  std::string known;
  for (const auto& [known_name, group] : boundaries) {
    known += known.empty() ? "'" : ", '";
    known += known_name + "'";
  }
  if (known.empty()) known = "none";
  throw InputError("mesh has no boundary named '" + name + "' (known boundaries: " + known + ")");
}

std::string Mesh::boundary_label(const BoundaryGroup& group) const {
  for (const auto& [name, candidate] : boundaries) {
    if (&candidate == &group) return "'" + name + "'";
  }
  return "(unnamed boundary)";
}

}  // namespace robin
