#include "coupling/mortar_rows.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "numerics/errors.hpp"

namespace robin {
namespace {

const FaceRowIntegrals& row_of(const FaceCoupling& coupling, int position) {
  return coupling.rows[static_cast<std::size_t>(position)];
}

/// Appends `values` (by position of `side`) divided by `scale`, times `normal`, to the row under
/// construction of `contact`, dropping round-off entries (below 1e-13 of the largest).
void add_entries(ContactOperator& contact, const MortarSide& side,
                 const std::map<int, double>& values, double scale, const Eigen::Vector3d& normal) {
  double largest = 0.0;
  for (const auto& [position, value] : values) largest = std::max(largest, std::abs(value));
  for (const auto& [position, value] : values) {
    if (std::abs(value) <= 1e-13 * largest) continue;
    const int node = side.interface->node_ids[static_cast<std::size_t>(position)];
    for (int component = 0; component < side.interface->dimension; ++component) {
      if (normal[component] != 0.0) {
        contact.add_entry(node, component, value / scale * normal[component]);
      }
    }
  }
}

std::string describe(const MortarSide& side, int position) {
  const Eigen::Vector3d& point = side.interface->coordinates[static_cast<std::size_t>(position)];
  std::string coordinates = std::to_string(point.x()) + ", " + std::to_string(point.y());
  if (side.interface->dimension == 3) coordinates += ", " + std::to_string(point.z());
  return "body '" + side.name + "' contact node (tag " +
         std::to_string(side.interface->node_tags[static_cast<std::size_t>(position)]) + ") at (" +
         coordinates + ")";
}

bool completely_covered(const MortarSide& nonmortar, const FaceCoupling& coupling, int position) {
  const double full = nonmortar.support[static_cast<std::size_t>(position)];
  return std::abs(row_of(coupling, position).covered - full) <= 1e-9 * full;
}

/// The non-mortar part of the dual row of a fully covered node, D_jk by position: D_jj alone or
/// the whole integrated row (DualRow).
std::map<int, double> dual_nonmortar_row(const FaceRowIntegrals& integrals, int position,
                                         DualRow dual_row) {
  if (dual_row == DualRow::full_row) return integrals.dual_nonmortar;
  return {{position, integrals.dual_nonmortar.at(position)}};
}

/// m_j = sum_k D_jk of the dual row (D_jj when the row is the node alone).
double dual_weight(const FaceRowIntegrals& integrals, int position, DualRow dual_row) {
  double weight = 0.0;
  for (const auto& [node, value] : dual_nonmortar_row(integrals, position, dual_row)) {
    weight += value;
  }
  return weight;
}

/// The constraint of non-mortar node `position` (before its operator rows are written).
ContactPair constraint_of(const MortarSide& nonmortar, const FaceCoupling& coupling, int position,
                          DualRow dual_row) {
  const FaceRowIntegrals& integrals = row_of(coupling, position);
  const bool complete = completely_covered(nonmortar, coupling, position);
  ContactPair pair;
  pair.normal = (nonmortar.body == 0 ? 1.0 : -1.0) *
                nonmortar.interface->normals[static_cast<std::size_t>(position)];
  // Both at the non-mortar node: where the constraint is (contact.csv, clearance checks).
  pair.position = nonmortar.interface->coordinates[static_cast<std::size_t>(position)];
  pair.position2 = pair.position;
  pair.weight = complete ? dual_weight(integrals, position, dual_row) : integrals.covered;
  pair.gap = (complete ? integrals.dual_gap : integrals.standard_gap) / pair.weight;
  const int node = nonmortar.interface->node_ids[static_cast<std::size_t>(position)];
  (nonmortar.body == 0 ? pair.node1 : pair.node2) = node;
  return pair;
}

/// Writes row `position` into both operators, divided by `weight`: the dual row (D on the
/// non-mortar side, -M on the mortar side) when the mortar side covers the node's support, else
/// the standard one.
void write_rows(const MortarSide& nonmortar, const MortarSide& mortar, const FaceCoupling& coupling,
                int position, double weight, DualRow dual_row, ContactPairing& pairing) {
  const FaceRowIntegrals& integrals = row_of(coupling, position);
  const Eigen::Vector3d& normal = nonmortar.interface->normals[static_cast<std::size_t>(position)];
  ContactOperator& own = pairing.operators[static_cast<std::size_t>(nonmortar.body)];
  ContactOperator& other = pairing.operators[static_cast<std::size_t>(mortar.body)];
  if (completely_covered(nonmortar, coupling, position)) {
    add_entries(own, nonmortar, dual_nonmortar_row(integrals, position, dual_row), weight, normal);
    add_entries(other, mortar, integrals.dual_mortar, -weight, normal);
  } else {
    add_entries(own, nonmortar, integrals.standard_nonmortar, weight, normal);
    add_entries(other, mortar, integrals.standard_mortar, -weight, normal);
  }
  own.finish_row(weight);
  other.finish_row(weight);
}

/// Throws InputError naming both bodies when no non-mortar node faces the mortar side.
void require_facing(const ContactPairing& pairing, const FaceCoupling& coupling,
                    const std::string& name1, const std::string& name2) {
  if (!pairing.pairs.empty() || !pairing.excluded.empty()) return;
  const std::string reason =
      coupling.same_direction_candidates > 0 && coupling.facing_candidates == 0
          ? "their outward normals point the same way (check which side of each body the "
            "contact boundary is on)"
          : "no point of one projects onto the other along its normals within reach (check "
            "that the two contact boundaries lie opposite each other)";
  throw InputError("mortar coupling: the contact boundaries of bodies '" + name1 + "' and '" +
                   name2 + "' do not face each other: " + reason);
}

}  // namespace

DualRow dual_row_of(FacetType nonmortar_facet_type) {
  return nonmortar_facet_type == FacetType::triangle6 ? DualRow::full_row : DualRow::node_alone;
}

ContactPairing assemble_mortar_rows(const MortarSide& nonmortar, const MortarSide& mortar,
                                    const FaceCoupling& coupling, DualRow dual_row) {
  ContactPairing pairing;
  std::vector<int> constrained;
  std::vector<Eigen::Vector3d> points;
  for (std::size_t j = 0; j < coupling.rows.size(); ++j) {
    const int position = static_cast<int>(j);
    if (!(coupling.rows[j].covered > 1e-3 * nonmortar.support[j])) continue;
    const Eigen::Vector3d& normal = nonmortar.interface->normals[j];
    if (normal_is_prescribed(nonmortar.interface->fixed[j], normal)) {
      pairing.excluded.push_back(describe(nonmortar, position) +
                                 ": normal displacement prescribed by a Dirichlet condition; "
                                 "constraint excluded from contact");
      pairing.excluded_pairs.push_back(constraint_of(nonmortar, coupling, position, dual_row));
      continue;
    }
    constrained.push_back(position);
    points.push_back(nonmortar.interface->coordinates[j]);
  }
  for (const std::size_t k : order_along_zone(points)) {
    const ContactPair pair = constraint_of(nonmortar, coupling, constrained[k], dual_row);
    write_rows(nonmortar, mortar, coupling, constrained[k], pair.weight, dual_row, pairing);
    pairing.pairs.push_back(pair);
  }
  const std::string& name1 = nonmortar.body == 0 ? nonmortar.name : mortar.name;
  const std::string& name2 = nonmortar.body == 0 ? mortar.name : nonmortar.name;
  require_facing(pairing, coupling, name1, name2);
  require_constraints_left(pairing, "mortar coupling", "constraints", name1, name2);
  pairing.non_mortar_body = nonmortar.body;
  pairing.uncovered = static_cast<int>(nonmortar.interface->node_ids.size()) -
                      static_cast<int>(pairing.pairs.size() + pairing.excluded.size());
  pairing.dimension = nonmortar.interface->dimension;
  return pairing;
}

}  // namespace robin
