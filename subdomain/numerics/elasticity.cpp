#include "numerics/elasticity.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

#include "numerics/errors.hpp"
#include "numerics/finite_element.hpp"

namespace robin {

namespace {

/// Degree of B^T C B on an affine element (bilinear quadrilaterals: the standard 2 x 2 rule).
int stiffness_degree(ElementType type) {
  switch (type) {
    case ElementType::triangle3:
      return 1;
    case ElementType::triangle6:
      return 2;
    case ElementType::quadrilateral4:
      return 3;
    case ElementType::tetrahedron4:
      return 1;
    case ElementType::tetrahedron10:
      return 2;
    case ElementType::hexahedron8:
      return 3;  // the standard 2 x 2 x 2 rule
  }
  throw std::invalid_argument("stiffness_degree: unknown element type");
}

/// Degree for loads N_i b(x) with a smooth b: two more than the shape functions' degree
/// squared, so that the load error stays below the discretization error.
int load_degree(ElementType type) {
  return type == ElementType::triangle6 || type == ElementType::tetrahedron10 ? 6 : 4;
}
int facet_load_degree(FacetType type) {
  return type == FacetType::line3 || type == FacetType::triangle6 ? 6 : 4;
}

/// The Voigt strain components as coordinate pairs (a, c): a normal strain e_aa = du_a/dx_a
/// when a = c, an engineering shear strain 2 e_ac = du_a/dx_c + du_c/dx_a otherwise. In 2D
/// (e_xx, e_yy, 2 e_xy), in 3D (e_xx, e_yy, e_zz, 2 e_yz, 2 e_xz, 2 e_xy) (material.hpp).
constexpr int plane_voigt_pairs[3][2] = {{0, 0}, {1, 1}, {0, 1}};
constexpr int solid_voigt_pairs[6][2] = {{0, 0}, {1, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}};

/// Strain-displacement matrix B (Voigt size x d n) of the physical gradients dN/dx (n x d):
/// strain = B u_e with u_e = (u_x0, u_y0, [u_z0,] u_x1, ...).
void strain_displacement(const ShapeGradients& gradients, StrainDisplacement& b) {
  const int count = static_cast<int>(gradients.rows());
  const int dimension = static_cast<int>(gradients.cols());
  const int voigt_size = dimension == 2 ? 3 : 6;
  const int(*pairs)[2] = dimension == 2 ? plane_voigt_pairs : solid_voigt_pairs;
  b.setZero(voigt_size, dimension * count);
  for (int row = 0; row < voigt_size; ++row) {
    const int a = pairs[row][0];
    const int c = pairs[row][1];
    for (int i = 0; i < count; ++i) {
      b(row, dimension * i + a) = gradients(i, c);
      if (a != c) b(row, dimension * i + c) = gradients(i, a);
    }
  }
}

/// The element's nodal displacements u_e (d n) gathered from the global vector.
void element_displacement(const Mesh& mesh, const ElementBlock& block, std::size_t element,
                          const Eigen::VectorXd& displacement, ElementVector& local) {
  const int count = nodes_per_element(block.type);
  const int dimension = mesh.dimension;
  local.resize(dimension * count);
  for (int i = 0; i < count; ++i) {
    const int node = block.connectivity[element * count + i];
    local.segment(dimension * i, dimension) = displacement.segment(dimension * node, dimension);
  }
}

void check_displacement_size(const Mesh& mesh, const Eigen::VectorXd& displacement,
                             const char* caller) {
  if (displacement.size() != static_cast<Eigen::Index>(mesh.dof_count())) {
    throw std::invalid_argument(std::string(caller) +
                                ": displacement size is not dimension x nodes");
  }
}

/// Throws InputError when the material's Voigt size is not that of the mesh's dimension.
void check_material_dimension(const Mesh& mesh, const Material& material) {
  if (material.dimension() != mesh.dimension) {
    throw InputError("a " + std::to_string(material.dimension()) + "D material (" +
                     std::to_string(material.voigt_size()) + " x " +
                     std::to_string(material.voigt_size()) + " Voigt stiffness) on the " +
                     std::to_string(mesh.dimension) + "D mesh" +
                     (mesh.source.empty() ? std::string() : " '" + mesh.source + "'") +
                     ": give a material of the mesh's dimension");
  }
}

/// Adds value * e_component at node `node` of a load vector of d-component nodes.
void add_nodal(Eigen::VectorXd& load, int dimension, int node, const Eigen::Vector3d& value) {
  load.segment(dimension * node, dimension) += value.head(dimension);
}

/// K_e = sum over `rule` (the element type's stiffness rule, tabulated) of B^T C B |J| w, with C
/// of fixed size (3 x 3 or 6 x 6: the products then have a fixed evaluation order, whatever the
/// dimension).
template <int VoigtSize>
void element_stiffness(const ElementGeometry& geometry, const std::vector<ReferenceShape>& rule,
                       const Eigen::Matrix<double, VoigtSize, VoigtSize>& c,
                       ElementMatrix& stiffness) {
  const int size = element_dimension(geometry.type()) * geometry.node_count();
  stiffness.setZero(size, size);
  StrainDisplacement b;
  for (const ReferenceShape& point : rule) {
    const ElementPoint at = geometry.evaluate(point);
    strain_displacement(at.gradients, b);
    // K_e += B^T C B |J| w
    stiffness.noalias() += b.transpose() * c * b * (at.jacobian * point.weight);
  }
}

/// The node graph of a mesh: node c shares an element with the nodes
/// neighbours[offsets[c]] .. neighbours[offsets[c+1] - 1] (itself included), ascending.
struct NodeGraph {
  std::vector<long> offsets;
  std::vector<int> neighbours;
  int degree(int node) const { return static_cast<int>(offsets[node + 1] - offsets[node]); }
};

NodeGraph node_graph(const Mesh& mesh) {
  const int node_count = static_cast<int>(mesh.node_count());
  // The elements of every node (incidences by block and element), counted then filled.
  std::vector<long> incidence_offsets(static_cast<std::size_t>(node_count) + 1, 0);
  for (const ElementBlock& block : mesh.blocks) {
    for (const int node : block.connectivity) ++incidence_offsets[node + 1];
  }
  for (int node = 0; node < node_count; ++node) {
    incidence_offsets[node + 1] += incidence_offsets[node];
  }
  std::vector<std::pair<int, std::size_t>> incidences(
      static_cast<std::size_t>(incidence_offsets[node_count]));
  std::vector<long> filled(incidence_offsets.begin(), incidence_offsets.end() - 1);
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const std::size_t count = static_cast<std::size_t>(nodes_per_element(block.type));
    for (std::size_t k = 0; k < block.connectivity.size(); ++k) {
      incidences[filled[block.connectivity[k]]++] = {static_cast<int>(b), k / count};
    }
  }
  NodeGraph graph;
  graph.offsets.assign(static_cast<std::size_t>(node_count) + 1, 0);
  std::vector<int> marked_by(static_cast<std::size_t>(node_count), -1);
  for (int node = 0; node < node_count; ++node) {
    const std::size_t first = graph.neighbours.size();
    for (long k = incidence_offsets[node]; k < incidence_offsets[node + 1]; ++k) {
      const ElementBlock& block = mesh.blocks[incidences[k].first];
      const std::size_t count = static_cast<std::size_t>(nodes_per_element(block.type));
      for (std::size_t i = 0; i < count; ++i) {
        const int other = block.connectivity[incidences[k].second * count + i];
        if (marked_by[other] == node) continue;
        marked_by[other] = node;
        graph.neighbours.push_back(other);
      }
    }
    std::sort(graph.neighbours.begin() + static_cast<std::ptrdiff_t>(first),
              graph.neighbours.end());
    graph.offsets[node + 1] = static_cast<long>(graph.neighbours.size());
  }
  return graph;
}

/// The pattern of K with zero values: column d c + b holds the rows d r + a of every neighbour
/// r of node c and every component a, ascending (r major), so node c's d columns start at
/// d^2 offsets[c] and have d degree(c) entries each.
SparseMatrix stiffness_pattern(const NodeGraph& graph, int dimension) {
  const int node_count = static_cast<int>(graph.offsets.size()) - 1;
  const long entry_count = long{dimension} * dimension * graph.offsets[node_count];
  if (entry_count > std::numeric_limits<int>::max()) {
    throw std::length_error("assemble_stiffness: more than 2^31 - 1 stiffness entries");
  }
  SparseMatrix pattern(dimension * node_count, dimension * node_count);
  pattern.resizeNonZeros(entry_count);
  int* column_starts = pattern.outerIndexPtr();
  int* rows = pattern.innerIndexPtr();
  long entry = 0;
  for (int node = 0; node < node_count; ++node) {
    for (int component = 0; component < dimension; ++component) {
      column_starts[dimension * node + component] = static_cast<int>(entry);
      for (long k = graph.offsets[node]; k < graph.offsets[node + 1]; ++k) {
        for (int row_component = 0; row_component < dimension; ++row_component) {
          rows[entry++] = dimension * graph.neighbours[k] + row_component;
        }
      }
    }
  }
  column_starts[dimension * node_count] = static_cast<int>(entry);
  std::fill(pattern.valuePtr(), pattern.valuePtr() + entry_count, 0.0);
  return pattern;
}

/// The position in stiffness_pattern's values of K(d row_node, d column_node): the first
/// column of column_node, at row_node's place among its neighbours.
long entry_offset(const NodeGraph& graph, int dimension, int row_node, int column_node) {
  const int* first = graph.neighbours.data() + graph.offsets[column_node];
  const int* last = graph.neighbours.data() + graph.offsets[column_node + 1];
  const long place = std::lower_bound(first, last, row_node) - first;
  return long{dimension} * dimension * graph.offsets[column_node] + long{dimension} * place;
}

/// Adds K_e of every element of block `b` into `stiffness` (stiffness_pattern's values): C of
/// fixed size VoigtSize.
template <int VoigtSize>
void add_block_stiffness(const Mesh& mesh, std::size_t b, const Material& material,
                         const NodeGraph& graph, double* values) {
  const ElementBlock& block = mesh.blocks[b];
  const int dimension = mesh.dimension;
  const int count = nodes_per_element(block.type);
  const std::vector<ReferenceShape> rule =
      tabulate_shapes(block.type, element_quadrature(block.type, stiffness_degree(block.type)));
  const Eigen::Matrix<double, VoigtSize, VoigtSize> c = material.stiffness;
  std::array<long, max_element_nodes * max_element_nodes> starts;
  ElementMatrix local;
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    element_stiffness<VoigtSize>({mesh, b, e}, rule, c, local);
    const int* nodes = &block.connectivity[e * count];
    for (int column = 0; column < count; ++column) {
      for (int row = 0; row < count; ++row) {
        starts[row * count + column] = entry_offset(graph, dimension, nodes[row], nodes[column]);
      }
    }
    // K(d r + a, d c + b) += K_e(d i + a, d j + b) for element nodes r = nodes[i], c = nodes[j],
    // in the order of i, a, j, b: every entry sums its elements' terms in element order.
    for (int i = 0; i < dimension * count; ++i) {
      for (int j = 0; j < dimension * count; ++j) {
        const long start = starts[(i / dimension) * count + j / dimension];
        const long column_length = long{dimension} * graph.degree(nodes[j / dimension]);
        values[start + (j % dimension) * column_length + i % dimension] += local(i, j);
      }
    }
  }
}

}  // namespace

SparseMatrix assemble_stiffness(const Mesh& mesh, const Material& material) {
  check_material_dimension(mesh, material);
  const NodeGraph graph = node_graph(mesh);
  SparseMatrix stiffness = stiffness_pattern(graph, mesh.dimension);
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    if (material.voigt_size() == 3) {
      add_block_stiffness<3>(mesh, b, material, graph, stiffness.valuePtr());
    } else {
      add_block_stiffness<6>(mesh, b, material, graph, stiffness.valuePtr());
    }
  }
  return stiffness;
}

Eigen::VectorXd assemble_body_force(const Mesh& mesh, const VectorField& body_force) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(mesh.dof_count());
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const int count = nodes_per_element(block.type);
    const std::vector<ReferenceShape> rule =
        tabulate_shapes(block.type, element_quadrature(block.type, load_degree(block.type)));
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      const ElementGeometry geometry(mesh, b, e);
      for (const ReferenceShape& point : rule) {
        const ElementPoint at = geometry.evaluate(point);
        // f_i += N_i b(x) |J| w
        const Eigen::Vector3d force = body_force(at.position) * (at.jacobian * point.weight);
        for (int i = 0; i < count; ++i) {
          add_nodal(load, mesh.dimension, block.connectivity[e * count + i], at.values(i) * force);
        }
      }
    }
  }
  return load;
}

Eigen::VectorXd assemble_boundary_traction(const Mesh& mesh, const BoundaryGroup& group,
                                           const TractionField& traction) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(mesh.dof_count());
  const NodeElementMap adjacency(mesh, group);
  const int count = nodes_per_facet(group.type);
  const std::vector<QuadraturePoint> rule =
      facet_quadrature(group.type, facet_load_degree(group.type));
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    const FacetGeometry facet(mesh, group, e, adjacency);
    for (const QuadraturePoint& point : rule) {
      const FacetPoint at = facet.evaluate(point.reference);
      // f_i += N_i t(x, n) |dx/dxi| w
      const Eigen::Vector3d force =
          traction(at.position, at.outward_normal) * (at.measure_element * point.weight);
      for (int i = 0; i < count; ++i) {
        add_nodal(load, mesh.dimension, group.connectivity[e * count + i], at.values(i) * force);
      }
    }
  }
  return load;
}

namespace {

/// Weights of a 6-node triangle's nodes from its four linear sub-triangles (corner, midside,
/// midside and the middle one of the three midside nodes): a third of each sub-triangle's area
/// to each of its corners. Positive, summing to the face's area (for a flat face).
void add_subtriangle_weights(const Mesh& mesh, const int* nodes, Eigen::VectorXd& weights) {
  constexpr int subtriangles[4][3] = {{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}};
  for (const auto& corners : subtriangles) {
    const Eigen::Vector3d& a = mesh.nodes[nodes[corners[0]]];
    const double area =
        0.5 * (mesh.nodes[nodes[corners[1]]] - a).cross(mesh.nodes[nodes[corners[2]]] - a).norm();
    for (const int corner : corners) weights(nodes[corner]) += area / 3.0;
  }
}

}  // namespace

Eigen::VectorXd boundary_weights(const Mesh& mesh, const BoundaryGroup& group) {
  Eigen::VectorXd weights = Eigen::VectorXd::Zero(mesh.node_count());
  const int count = nodes_per_facet(group.type);
  if (group.type == FacetType::triangle6) {
    for (std::size_t e = 0; e < group.facet_count(); ++e) {
      add_subtriangle_weights(mesh, &group.connectivity[e * count], weights);
    }
    return weights;
  }
  const std::vector<QuadraturePoint> rule =
      facet_quadrature(group.type, facet_load_degree(group.type));
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    const FacetGeometry facet(mesh, group, e);
    for (const QuadraturePoint& point : rule) {
      const FacetPoint at = facet.evaluate(point.reference);
      // m_i += N_i |dx/dxi| w
      for (int i = 0; i < count; ++i) {
        weights(group.connectivity[e * count + i]) +=
            at.values(i) * at.measure_element * point.weight;
      }
    }
  }
  return weights;
}

std::vector<Eigen::Vector3d> boundary_normal_sums(const Mesh& mesh, const BoundaryGroup& group,
                                                  bool facets_oriented_outward) {
  std::optional<NodeElementMap> adjacency;
  if (!facets_oriented_outward) adjacency.emplace(mesh, group);
  const int count = nodes_per_facet(group.type);
  const std::vector<Eigen::Vector3d> node_references = facet_reference_nodes(group.type);
  std::vector<Eigen::Vector3d> sums(mesh.node_count(), Eigen::Vector3d::Zero());
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    const FacetGeometry facet =
        adjacency ? FacetGeometry(mesh, group, e, *adjacency) : FacetGeometry(mesh, group, e);
    const double measure = facet.measure();
    for (int i = 0; i < count; ++i) {
      // Each node receives its facets' outward normals (taken at the node) times their measures.
      sums[group.connectivity[e * count + i]] +=
          measure * facet.evaluate(node_references[i]).outward_normal;
    }
  }
  return sums;
}

std::vector<Eigen::Vector3d> unit_normals(const Mesh& mesh,
                                          const std::vector<Eigen::Vector3d>& sums,
                                          const std::vector<int>& nodes, const std::string& what) {
  std::vector<Eigen::Vector3d> normals;
  normals.reserve(nodes.size());
  for (const int node : nodes) {
    const double norm = sums[node].norm();
    if (norm == 0.0) {
      throw InputError(what + ": the normals at node " + std::to_string(mesh.node_tags[node]) +
                       " cancel out (a cusp or a fold)");
    }
    normals.push_back(sums[node] / norm);
  }
  return normals;
}

std::vector<Eigen::Vector3d> boundary_node_normals(const Mesh& mesh, const BoundaryGroup& group) {
  return unit_normals(mesh, boundary_normal_sums(mesh, group), group.nodes(),
                      "boundary " + mesh.boundary_label(group));
}

namespace {

/// The Voigt stress s = C B u_e of an element at a tabulated point of its type (b: scratch).
VoigtVector stress_at(const ElementGeometry& geometry, const ReferenceShape& shape,
                      const VoigtMatrix& c, const ElementVector& local, StrainDisplacement& b) {
  strain_displacement(geometry.evaluate(shape).gradients, b);
  return c * (b * local);
}

/// Calls `visit` for every element of block `b` (for_each_element_stress), any element type.
void visit_block_stresses(const Mesh& mesh, std::size_t b, const VoigtMatrix& c,
                          const Eigen::VectorXd& displacement, const ElementStressVisitor& visit) {
  const ElementBlock& block = mesh.blocks[b];
  std::vector<Eigen::Vector3d> points{reference_centroid(block.type)};
  for (const Eigen::Vector3d& node : reference_nodes(block.type)) points.push_back(node);
  const std::vector<ReferenceShape> shapes = tabulate_shapes(block.type, points);
  const std::vector<std::size_t> same = first_with_same_gradients(shapes);
  std::array<VoigtVector, max_element_nodes + 1> stresses;  // centroid, then node by node
  ElementVector local;
  StrainDisplacement scratch;
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    const ElementGeometry geometry(mesh, b, e);
    element_displacement(mesh, block, e, displacement, local);
    for (std::size_t k = 0; k < shapes.size(); ++k) {
      stresses[k] =
          same[k] == k ? stress_at(geometry, shapes[k], c, local, scratch) : stresses[same[k]];
    }
    visit(geometry.nodes(), geometry.node_count(), stresses.data());
  }
}

/// The same for a block of affine simplices (3-node triangles in 2D, 4-node tetrahedra in 3D),
/// whose dN/dx is constant: with J = [x_1 - x_0, ..., x_d - x_0] (J_ij = dx_i / dxi_j) and
/// U = [u_1 - u_0, ..., u_d - u_0], the displacement gradient is H = U J^-1 (H_ac = du_a/dx_c),
/// the Voigt strain has H_aa and H_ac + H_ca, and one stress C strain holds at the centroid
/// and at every node. An element with det J <= 0 gets ElementGeometry's error.
template <int Dimension>
void visit_affine_block_stresses(const Mesh& mesh, std::size_t b, const VoigtMatrix& c,
                                 const Eigen::VectorXd& displacement,
                                 const ElementStressVisitor& visit) {
  constexpr int count = Dimension + 1;
  constexpr int voigt_size = Dimension == 2 ? 3 : 6;
  const int(*pairs)[2] = Dimension == 2 ? plane_voigt_pairs : solid_voigt_pairs;
  using Square = Eigen::Matrix<double, Dimension, Dimension>;
  const Eigen::Matrix<double, voigt_size, voigt_size> stiffness = c;
  const ElementBlock& block = mesh.blocks[b];
  std::array<VoigtVector, count + 1> stresses;  // centroid, then node by node: all equal
  for (std::size_t e = 0; e < block.element_count(); ++e) {
    const int* nodes = &block.connectivity[e * count];
    Square jacobian;
    Square differences;
    for (int j = 0; j < Dimension; ++j) {
      jacobian.col(j) =
          (mesh.nodes[nodes[j + 1]] - mesh.nodes[nodes[0]]).template head<Dimension>();
      differences.col(j) = displacement.template segment<Dimension>(Dimension * nodes[j + 1]) -
                           displacement.template segment<Dimension>(Dimension * nodes[0]);
    }
    if (!(jacobian.determinant() > 0.0)) {
      ElementGeometry(mesh, b, e).evaluate(reference_centroid(block.type));  // throws
    }
    const Square gradient = differences * jacobian.inverse();
    Eigen::Matrix<double, voigt_size, 1> strain;
    for (int row = 0; row < voigt_size; ++row) {
      const int first = pairs[row][0];
      const int second = pairs[row][1];
      strain(row) = first == second ? gradient(first, first)
                                    : gradient(first, second) + gradient(second, first);
    }
    stresses[0] = stiffness * strain;
    for (int k = 1; k <= count; ++k) stresses[k] = stresses[0];
    visit(nodes, count, stresses.data());
  }
}

/// The von Mises stress of each column of `stresses` (Voigt stresses of `material`).
Eigen::VectorXd von_mises_of(const Material& material, const Eigen::MatrixXd& stresses) {
  Eigen::VectorXd values(stresses.cols());
  for (Eigen::Index k = 0; k < stresses.cols(); ++k) {
    values(k) = von_mises(material, stresses.col(k));
  }
  return values;
}

}  // namespace

void for_each_element_stress(const Mesh& mesh, const Material& material,
                             const Eigen::VectorXd& displacement,
                             const ElementStressVisitor& visit) {
  check_displacement_size(mesh, displacement, "for_each_element_stress");
  check_material_dimension(mesh, material);
  const VoigtMatrix c = material.stiffness;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementType type = mesh.blocks[b].type;
    if (type == ElementType::triangle3 && mesh.dimension == 2) {
      visit_affine_block_stresses<2>(mesh, b, c, displacement, visit);
    } else if (type == ElementType::tetrahedron4 && mesh.dimension == 3) {
      visit_affine_block_stresses<3>(mesh, b, c, displacement, visit);
    } else {
      visit_block_stresses(mesh, b, c, displacement, visit);
    }
  }
}

StressField recover_stress(const Mesh& mesh, const Material& material,
                           const Eigen::VectorXd& displacement) {
  StressField field;
  field.element_stress.resize(material.voigt_size(),
                              static_cast<Eigen::Index>(mesh.element_count()));
  field.nodal_stress =
      Eigen::MatrixXd::Zero(material.voigt_size(), static_cast<Eigen::Index>(mesh.node_count()));
  Eigen::VectorXd touching = Eigen::VectorXd::Zero(mesh.node_count());
  Eigen::Index element = 0;
  for_each_element_stress(mesh, material, displacement,
                          [&](const int* nodes, int count, const VoigtVector* stresses) {
                            field.element_stress.col(element++) = stresses[0];
                            for (int i = 0; i < count; ++i) {
                              field.nodal_stress.col(nodes[i]) += stresses[i + 1];
                              touching(nodes[i]) += 1.0;
                            }
                          });
  for (Eigen::Index node = 0; node < touching.size(); ++node) {
    if (touching(node) > 0.0) field.nodal_stress.col(node) /= touching(node);
  }
  field.element_von_mises = von_mises_of(material, field.element_stress);
  field.nodal_von_mises = von_mises_of(material, field.nodal_stress);
  return field;
}

double l2_displacement_error(const Mesh& mesh, const Eigen::VectorXd& displacement,
                             const VectorField& exact) {
  check_displacement_size(mesh, displacement, "l2_displacement_error");
  double sum = 0.0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const int count = nodes_per_element(block.type);
    const std::vector<ReferenceShape> rule =
        tabulate_shapes(block.type, element_quadrature(block.type, 6));
    ElementVector local;
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      const ElementGeometry geometry(mesh, b, e);
      element_displacement(mesh, block, e, displacement, local);
      const int dimension = mesh.dimension;
      for (const ReferenceShape& point : rule) {
        const ElementPoint at = geometry.evaluate(point);
        Eigen::Vector3d approximate = Eigen::Vector3d::Zero();
        for (int i = 0; i < count; ++i) {
          approximate.head(dimension) += at.values(i) * local.segment(dimension * i, dimension);
        }
        // ||u_h - u||^2 += |u_h(x) - u(x)|^2 |J| w
        sum += (approximate - exact(at.position)).squaredNorm() * at.jacobian * point.weight;
      }
    }
  }
  return std::sqrt(sum);
}

}  // namespace robin
