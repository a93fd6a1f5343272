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
    case ElementType::tetrahedron4:
      return 4;
    case ElementType::tetrahedron10:
      return 10;
    case ElementType::hexahedron8:
      return 8;
  }
  throw std::invalid_argument("nodes_per_element: unknown element type");
}

int nodes_per_facet(FacetType type) {
  switch (type) {
    case FacetType::line2:
      return 2;
    case FacetType::line3:
      return 3;
    case FacetType::triangle3:
      return 3;
    case FacetType::triangle6:
      return 6;
    case FacetType::quadrilateral4:
      return 4;
  }
  throw std::invalid_argument("nodes_per_facet: unknown facet type");
}

int element_corner_count(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
    case ElementType::triangle6:
      return 3;
    case ElementType::quadrilateral4:
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
      return 4;
    case ElementType::hexahedron8:
      return 8;
  }
  throw std::invalid_argument("element_corner_count: unknown element type");
}

int facet_corner_count(FacetType type) {
  switch (type) {
    case FacetType::line2:
    case FacetType::line3:
      return 2;
    case FacetType::triangle3:
    case FacetType::triangle6:
      return 3;
    case FacetType::quadrilateral4:
      return 4;
  }
  throw std::invalid_argument("facet_corner_count: unknown facet type");
}

int element_dimension(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
    case ElementType::triangle6:
    case ElementType::quadrilateral4:
      return 2;
    case ElementType::tetrahedron4:
    case ElementType::tetrahedron10:
    case ElementType::hexahedron8:
      return 3;
  }
  throw std::invalid_argument("element_dimension: unknown element type");
}

int facet_dimension(FacetType type) {
  switch (type) {
    case FacetType::line2:
    case FacetType::line3:
      return 1;
    case FacetType::triangle3:
    case FacetType::triangle6:
    case FacetType::quadrilateral4:
      return 2;
  }
  throw std::invalid_argument("facet_dimension: unknown facet type");
}

ElementType face_parametrization(FacetType type) {
  switch (type) {
    case FacetType::triangle3:
      return ElementType::triangle3;
    case FacetType::triangle6:
      return ElementType::triangle6;
    case FacetType::quadrilateral4:
      return ElementType::quadrilateral4;
    case FacetType::line2:
    case FacetType::line3:
      break;
  }
  throw std::invalid_argument("face_parametrization: an edge is not a face");
}

std::string to_string(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return "triangle3";
    case ElementType::triangle6:
      return "triangle6";
    case ElementType::quadrilateral4:
      return "quadrilateral4";
    case ElementType::tetrahedron4:
      return "tetrahedron4";
    case ElementType::tetrahedron10:
      return "tetrahedron10";
    case ElementType::hexahedron8:
      return "hexahedron8";
  }
  throw std::invalid_argument("to_string: unknown element type");
}

std::string to_string(FacetType type) {
  switch (type) {
    case FacetType::line2:
      return "line2";
    case FacetType::line3:
      return "line3";
    case FacetType::triangle3:
      return "triangle3";
    case FacetType::triangle6:
      return "triangle6";
    case FacetType::quadrilateral4:
      return "quadrilateral4";
  }
  throw std::invalid_argument("to_string: unknown facet type");
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
