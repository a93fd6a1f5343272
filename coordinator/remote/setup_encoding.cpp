#include "remote/setup_encoding.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <optional>

#include "mesh_codec.hpp"
#include "numerics/errors.hpp"

namespace robin {

namespace {

/// Young's modulus E for which make_isotropic_material(E, nu, plane strain) yields `stiffness`
/// exactly, searched a few ulps around the closed form E = C_00 (1 + nu)(1 - 2 nu) / (1 - nu);
/// nullopt when no such E exists (C is not isotropic with this nu).
std::optional<double> exact_young_modulus(const Eigen::MatrixXd& stiffness, double nu) {
  const double closed_form = stiffness(0, 0) * (1.0 + nu) * (1.0 - 2.0 * nu) / (1.0 - nu);
  if (!(closed_form > 0.0) || !std::isfinite(closed_form)) return std::nullopt;
  double below = closed_form, above = closed_form;
  for (int step = 0; step <= 16; ++step) {
    for (double candidate : {below, above}) {
      const Material rebuilt = make_isotropic_material(candidate, nu, PlaneModel::plane_strain, "");
      if (rebuilt.stiffness == stiffness) return candidate;
    }
    below = std::nextafter(below, 0.0);
    above = std::nextafter(above, 2.0 * closed_form);
  }
  const Material rebuilt = make_isotropic_material(closed_form, nu, PlaneModel::plane_strain, "");
  const double scale = stiffness.cwiseAbs().maxCoeff();
  if ((rebuilt.stiffness - stiffness).cwiseAbs().maxCoeff() <= 1e-14 * scale) return closed_form;
  return std::nullopt;
}

void encode_dirichlet(const DirichletCondition& condition, protocol::Dirichlet& message) {
  message.set_boundary(condition.boundary);
  if (condition.x) message.set_x(*condition.x);
  if (condition.y) message.set_y(*condition.y);
  if (condition.z) message.set_z(*condition.z);
}

void encode_traction(const TractionCondition& condition, int dimension,
                     protocol::Traction& message) {
  message.set_boundary(condition.boundary);
  message.set_is_pressure(condition.is_pressure);
  if (condition.is_pressure) {
    message.set_pressure(condition.pressure);
  } else {
    for (int component = 0; component < dimension; ++component) {
      message.add_vector(condition.vector[component]);
    }
  }
}

std::string interface_operator_name(InterfaceOperatorKind kind) {
  switch (kind) {
    case InterfaceOperatorKind::dense:
      return "dense";
    case InterfaceOperatorKind::factor:
      return "factor";
    case InterfaceOperatorKind::automatic:
      break;
  }
  return "auto";
}

/// The solver settings, with `linear_solver` (resolved: never automatic) for the case's choice.
void encode_solver(const SolverOptions& solver, LinearSolverKind linear_solver,
                   protocol::SolverSettings& message) {
  message.set_qp_tolerance(solver.qp.relative_tolerance);
  message.set_qp_max_iterations(static_cast<std::uint32_t>(solver.qp.max_iterations));
  message.set_interface_operator(interface_operator_name(solver.body.interface_operator));
  message.set_dense_limit(static_cast<std::uint32_t>(std::max(solver.body.dense_limit, 0)));
  message.set_linear_solver(linear_solver_name(linear_solver));
}

}  // namespace

void encode_material(const Material& material, const std::string& context,
                     protocol::SetupBody& message) {
  if (material.out_of_plane_poisson != 0.0) {
    const double nu = material.out_of_plane_poisson;
    const auto young = material.model == PlaneModel::plane_strain
                           ? exact_young_modulus(material.stiffness, nu)
                           : std::nullopt;
    if (!young) {
      throw InputError(context +
                       ": material: an out-of-plane stress factor with a non-isotropic "
                       "stiffness cannot be sent in the protocol (give young and poisson)");
    }
    message.set_young_modulus(*young);
    message.set_poisson_ratio(nu);
    return;
  }
  const int size = material.voigt_size();  // 3 (plane) or 6 (solid: always sent as `voigt`)
  for (int row = 0; row < size; ++row) {
    for (int column = 0; column < size; ++column) {
      message.add_voigt(material.stiffness(row, column));
    }
  }
}

namespace {

/// Everything of the SetupBody request but the mesh, for a mesh of `dimension` with
/// `dof_count` degrees of freedom (the automatic choice of the linear solver).
protocol::SetupBody encode_body_without_mesh(const BodyDefinition& definition,
                                             const std::string& context,
                                             const SolverOptions& solver, bool floating,
                                             int dimension, long dof_count) {
  protocol::SetupBody message;
  message.set_body_name(definition.name);
  if (definition.material.dimension() != dimension) {
    throw InputError(context + ": material: a " +
                     (definition.material.dimension() == 3 ? "solid (6x6)" : "plane (3x3)") +
                     " material for a " + (dimension == 3 ? "solid" : "plane") + " mesh");
  }
  if (dimension == 2) {  // a solid body has no plane model (left unspecified)
    message.set_model(definition.material.model == PlaneModel::plane_strain
                          ? protocol::PLANE_STRAIN
                          : protocol::PLANE_STRESS);
  }
  encode_material(definition.material, context, message);
  for (int component = 0; component < dimension; ++component) {
    message.add_body_force(definition.body_force[component]);
  }
  for (const DirichletCondition& condition : definition.dirichlet) {
    encode_dirichlet(condition, *message.add_dirichlet());
  }
  for (const TractionCondition& condition : definition.tractions) {
    encode_traction(condition, dimension, *message.add_traction());
  }
  for (const std::string& boundary : definition.contact_boundaries) {
    message.add_contact_boundaries(boundary);
  }
  // the automatic choice is made here: servers get "direct" or "multigrid"
  const LinearSolverKind linear_solver =
      resolve_linear_solver(solver.body.linear_solver, dimension, dof_count,
                            floating ? RigidMotions::held_by_contact : RigidMotions::refuse);
  encode_solver(solver, linear_solver, *message.mutable_solver());
  message.set_floating(floating);
  return message;
}

}  // namespace

protocol::SetupBody encode_setup_body(const BodyDefinition& definition, const std::string& context,
                                      const SolverOptions& solver, bool floating) {
  protocol::SetupBody message =
      encode_body_without_mesh(definition, context, solver, floating, definition.mesh.dimension,
                               static_cast<long>(definition.mesh.dof_count()));
  *message.mutable_mesh() = encode_mesh(definition.mesh);
  return message;
}

protocol::SetupBody encode_setup_body(const BodyCase& body, const SolverOptions& solver) {
  if (body.mesh_delivery == MeshDelivery::data) {
    return encode_setup_body(body.definition, body.context, solver, body.floating);
  }
  const long dof_count = body.dimension * static_cast<long>(body.mesh_file_node_count);
  protocol::SetupBody message = encode_body_without_mesh(body.definition, body.context, solver,
                                                         body.floating, body.dimension, dof_count);
  message.set_mesh_path(body.server_mesh_path);
  return message;
}

protocol::AssignContact encode_contact_operator(const ContactOperator& contact) {
  protocol::AssignContact message;
  message.mutable_row_offsets()->Assign(contact.row_offsets.begin(), contact.row_offsets.end());
  message.mutable_node_ids()->Assign(contact.nodes.begin(), contact.nodes.end());
  message.mutable_components()->Assign(contact.components.begin(), contact.components.end());
  message.mutable_values()->Assign(contact.values.begin(), contact.values.end());
  message.mutable_weights()->Assign(contact.weights.begin(), contact.weights.end());
  return message;
}

}  // namespace robin
