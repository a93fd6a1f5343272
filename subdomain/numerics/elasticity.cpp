#include "numerics/elasticity.hpp"

#include <Eigen/LU>
#include <cmath>
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
    case ElementType::tetrahedron10:
    case ElementType::hexahedron8:
      break;
  }
  throw std::invalid_argument("stiffness_degree: unknown element type");
}

/// Degree for loads N_i b(x) with a smooth b: two more than the shape functions' degree
/// squared, so that the load error stays below the discretization error.
int load_degree(ElementType type) {
  return type == ElementType::triangle6 ? 6 : 4;
}
int edge_load_degree(FacetType type) {
  return type == FacetType::line3 ? 6 : 4;
}

/// Strain-displacement matrix B (3 x 2n): strain (e_xx, e_yy, 2 e_xy) = B u_e, with
/// u_e = (u_x0, u_y0, u_x1, ...).
Eigen::MatrixXd strain_displacement(const Eigen::MatrixXd& gradients) {
  const Eigen::Index count = gradients.rows();
  Eigen::MatrixXd b = Eigen::MatrixXd::Zero(3, 2 * count);
  for (Eigen::Index i = 0; i < count; ++i) {
    b(0, 2 * i) = gradients(i, 0);
    b(1, 2 * i + 1) = gradients(i, 1);
    b(2, 2 * i) = gradients(i, 1);
    b(2, 2 * i + 1) = gradients(i, 0);
  }
  return b;
}

Eigen::VectorXd element_displacement(const ElementBlock& block, std::size_t element,
                                     const Eigen::VectorXd& displacement) {
  const int count = nodes_per_element(block.type);
  Eigen::VectorXd local(2 * count);
  for (int i = 0; i < count; ++i) {
    const int node = block.connectivity[element * count + i];
    local.segment<2>(2 * i) = displacement.segment<2>(2 * node);
  }
  return local;
}

void check_displacement_size(const Mesh& mesh, const Eigen::VectorXd& displacement,
                             const char* caller) {
  if (displacement.size() != static_cast<Eigen::Index>(2 * mesh.node_count())) {
    throw std::invalid_argument(std::string(caller) + ": displacement size is not 2 x nodes");
  }
}

Eigen::MatrixXd element_stiffness(const ElementGeometry& geometry, const Eigen::Matrix3d& c) {
  const int count = geometry.node_count();
  Eigen::MatrixXd stiffness = Eigen::MatrixXd::Zero(2 * count, 2 * count);
  for (const QuadraturePoint& point :
       element_quadrature(geometry.type(), stiffness_degree(geometry.type()))) {
    const ElementPoint at = geometry.evaluate(point.reference);
    const Eigen::MatrixXd b = strain_displacement(at.gradients);
    // K_e += B^T C B |J| w
    stiffness.noalias() += b.transpose() * c * b * (at.jacobian * point.weight);
  }
  return stiffness;
}

}  // namespace

SparseMatrix assemble_stiffness(const Mesh& mesh, const Material& material) {
  std::vector<Eigen::Triplet<double>> triplets;
  std::size_t reserve = 0;
  for (const ElementBlock& block : mesh.blocks) {
    const std::size_t size = 2 * nodes_per_element(block.type);
    reserve += block.element_count() * size * size;
  }
  triplets.reserve(reserve);
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const int count = nodes_per_element(block.type);
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      const Eigen::MatrixXd local = element_stiffness({mesh, b, e}, material.stiffness);
      const int* nodes = &block.connectivity[e * count];
      for (int i = 0; i < 2 * count; ++i) {
        for (int j = 0; j < 2 * count; ++j) {
          triplets.emplace_back(2 * nodes[i / 2] + i % 2, 2 * nodes[j / 2] + j % 2, local(i, j));
        }
      }
    }
  }
  const int size = static_cast<int>(2 * mesh.node_count());
  SparseMatrix stiffness(size, size);
  stiffness.setFromTriplets(triplets.begin(), triplets.end());
  return stiffness;
}

Eigen::VectorXd assemble_body_force(const Mesh& mesh, const VectorField& body_force) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(2 * mesh.node_count());
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const int count = nodes_per_element(block.type);
    const std::vector<QuadraturePoint> rule =
        element_quadrature(block.type, load_degree(block.type));
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      const ElementGeometry geometry(mesh, b, e);
      for (const QuadraturePoint& point : rule) {
        const ElementPoint at = geometry.evaluate(point.reference);
        // f_i += N_i b(x) |J| w
        const Eigen::Vector2d force = body_force(at.position) * (at.jacobian * point.weight);
        for (int i = 0; i < count; ++i) {
          load.segment<2>(2 * block.connectivity[e * count + i]) += at.values(i) * force;
        }
      }
    }
  }
  return load;
}

Eigen::VectorXd assemble_boundary_traction(const Mesh& mesh, const BoundaryGroup& group,
                                           const TractionField& traction) {
  Eigen::VectorXd load = Eigen::VectorXd::Zero(2 * mesh.node_count());
  const NodeElementMap adjacency(mesh);
  const int count = nodes_per_facet(group.type);
  const std::vector<QuadraturePoint> rule = edge_quadrature(edge_load_degree(group.type));
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    const EdgeGeometry edge(mesh, group, e, adjacency);
    for (const QuadraturePoint& point : rule) {
      const EdgePoint at = edge.evaluate(point.reference.x());
      // f_i += N_i t(x, n) |dx/dt| w
      const Eigen::Vector2d force =
          traction(at.position, at.outward_normal) * (at.length_element * point.weight);
      for (int i = 0; i < count; ++i) {
        load.segment<2>(2 * group.connectivity[e * count + i]) += at.values(i) * force;
      }
    }
  }
  return load;
}

Eigen::VectorXd boundary_weights(const Mesh& mesh, const BoundaryGroup& group) {
  Eigen::VectorXd weights = Eigen::VectorXd::Zero(mesh.node_count());
  const int count = nodes_per_facet(group.type);
  const std::vector<QuadraturePoint> rule = edge_quadrature(edge_load_degree(group.type));
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    const EdgeGeometry edge(mesh, group, e);
    for (const QuadraturePoint& point : rule) {
      const EdgePoint at = edge.evaluate(point.reference.x());
      // m_i += N_i |dx/dt| w
      for (int i = 0; i < count; ++i) {
        weights(group.connectivity[e * count + i]) +=
            at.values(i) * at.length_element * point.weight;
      }
    }
  }
  return weights;
}

std::vector<Eigen::Vector2d> boundary_normal_sums(const Mesh& mesh, const BoundaryGroup& group,
                                                  bool edges_have_body_on_left) {
  std::optional<NodeElementMap> adjacency;
  if (!edges_have_body_on_left) adjacency.emplace(mesh);
  const int count = nodes_per_facet(group.type);
  const std::vector<double> node_references = edge_reference_nodes(group.type);
  std::vector<Eigen::Vector2d> sums(mesh.node_count(), Eigen::Vector2d::Zero());
  for (std::size_t e = 0; e < group.facet_count(); ++e) {
    const EdgeGeometry edge =
        adjacency ? EdgeGeometry(mesh, group, e, *adjacency) : EdgeGeometry(mesh, group, e);
    const double length = edge.length();
    for (int i = 0; i < count; ++i) {
      // Each node receives its edges' outward normals (taken at the node) times their lengths.
      sums[group.connectivity[e * count + i]] +=
          length * edge.evaluate(node_references[i]).outward_normal;
    }
  }
  return sums;
}

std::vector<Eigen::Vector2d> unit_normals(const Mesh& mesh,
                                          const std::vector<Eigen::Vector2d>& sums,
                                          const std::vector<int>& nodes, const std::string& what) {
  std::vector<Eigen::Vector2d> normals;
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

std::vector<Eigen::Vector2d> boundary_node_normals(const Mesh& mesh, const BoundaryGroup& group) {
  return unit_normals(mesh, boundary_normal_sums(mesh, group), group.nodes(),
                      "boundary " + mesh.boundary_label(group));
}

StressField recover_stress(const Mesh& mesh, const Material& material,
                           const Eigen::VectorXd& displacement) {
  check_displacement_size(mesh, displacement, "recover_stress");
  StressField field;
  field.element_stress.resize(3, static_cast<Eigen::Index>(mesh.element_count()));
  field.nodal_stress = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(mesh.node_count()));
  Eigen::VectorXd touching = Eigen::VectorXd::Zero(mesh.node_count());
  Eigen::Index flat = 0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const std::vector<Eigen::Vector2d> node_references = reference_nodes(block.type);
    for (std::size_t e = 0; e < block.element_count(); ++e, ++flat) {
      const ElementGeometry geometry(mesh, b, e);
      const Eigen::VectorXd local = element_displacement(block, e, displacement);
      // s = C B u_e
      const auto stress_at = [&](const Eigen::Vector2d& reference) -> Eigen::Vector3d {
        return material.stiffness *
               (strain_displacement(geometry.evaluate(reference).gradients) * local);
      };
      field.element_stress.col(flat) = stress_at(reference_centroid(block.type));
      for (int i = 0; i < geometry.node_count(); ++i) {
        const int node = geometry.node(i);
        field.nodal_stress.col(node) += stress_at(node_references[i]);
        touching(node) += 1.0;
      }
    }
  }
  for (Eigen::Index node = 0; node < touching.size(); ++node) {
    if (touching(node) > 0.0) field.nodal_stress.col(node) /= touching(node);
  }
  const auto von_mises_of = [&](const Eigen::Matrix3Xd& stresses) {
    Eigen::VectorXd values(stresses.cols());
    for (Eigen::Index k = 0; k < stresses.cols(); ++k) {
      values(k) = von_mises(material, stresses.col(k));
    }
    return values;
  };
  field.element_von_mises = von_mises_of(field.element_stress);
  field.nodal_von_mises = von_mises_of(field.nodal_stress);
  return field;
}

double l2_displacement_error(const Mesh& mesh, const Eigen::VectorXd& displacement,
                             const VectorField& exact) {
  check_displacement_size(mesh, displacement, "l2_displacement_error");
  double sum = 0.0;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    const ElementBlock& block = mesh.blocks[b];
    const int count = nodes_per_element(block.type);
    const std::vector<QuadraturePoint> rule = element_quadrature(block.type, 6);
    for (std::size_t e = 0; e < block.element_count(); ++e) {
      const ElementGeometry geometry(mesh, b, e);
      const Eigen::VectorXd local = element_displacement(block, e, displacement);
      for (const QuadraturePoint& point : rule) {
        const ElementPoint at = geometry.evaluate(point.reference);
        Eigen::Vector2d approximate = Eigen::Vector2d::Zero();
        for (int i = 0; i < count; ++i) approximate += at.values(i) * local.segment<2>(2 * i);
        // ||u_h - u||^2 += |u_h(x) - u(x)|^2 |J| w
        sum += (approximate - exact(at.position)).squaredNorm() * at.jacobian * point.weight;
      }
    }
  }
  return std::sqrt(sum);
}

}  // namespace robin
