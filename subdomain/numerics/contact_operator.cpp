#include "numerics/contact_operator.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "numerics/errors.hpp"

namespace robin {

void ContactOperator::add_entry(int node, int component, double value) {
  nodes.push_back(node);
  components.push_back(component);
  values.push_back(value);
}

void ContactOperator::finish_row(double weight) {
  row_offsets.push_back(values.size());
  weights.push_back(weight);
}

bool operator==(const ContactOperator& left, const ContactOperator& right) {
  return left.row_offsets == right.row_offsets && left.nodes == right.nodes &&
         left.components == right.components && left.values == right.values &&
         left.weights == right.weights;
}

ContactOperator node_to_node_operator(const std::vector<int>& nodes,
                                      const std::vector<Eigen::Vector3d>& normals,
                                      const std::vector<double>& weights) {
  ContactOperator contact;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    contact.add_entry(nodes[i], 0, normals[i].x());
    contact.add_entry(nodes[i], 1, normals[i].y());
    // Plane bodies' normals have z = 0: their rows keep the two entries x, y.
    if (normals[i].z() != 0.0) contact.add_entry(nodes[i], 2, normals[i].z());
    contact.finish_row(weights[i]);
  }
  return contact;
}

namespace {

void check_offsets(const ContactOperator& contact, const std::string& context) {
  const auto fail = [&](const std::string& problem) {
    throw InputError(context + ": AssignContact.row_offsets" + problem);
  };
  if (contact.row_offsets.empty() || contact.row_offsets.front() != 0) {
    fail(" must start with 0 (one more entry than there are constraints)");
  }
  if (contact.row_offsets.back() != contact.entry_count()) {
    fail(" ends at " + std::to_string(contact.row_offsets.back()) + ", expected the entry count " +
         std::to_string(contact.entry_count()));
  }
  for (int row = 0; row < contact.row_count(); ++row) {
    if (contact.row_offsets[row + 1] <= contact.row_offsets[row]) {
      std::ostringstream problem;
      problem << "[" << row + 1 << "] leaves constraint " << row
              << " without entries (offsets must increase)";
      fail(problem.str());
    }
  }
  if (contact.row_count() < 1) fail(" describes no constraint");
}

void check_row(const ContactOperator& contact, int row, const std::vector<int>& contact_nodes,
               int dimension, const std::string& context) {
  std::vector<std::pair<int, int>> seen;
  for (std::size_t k = contact.row_offsets[row]; k < contact.row_offsets[row + 1]; ++k) {
    std::string entry = std::to_string(k);
    entry.insert(entry.begin(), '[');
    entry.push_back(']');
    const int node = contact.nodes[k];
    if (!std::binary_search(contact_nodes.begin(), contact_nodes.end(), node)) {
      throw InputError(
          context + ": AssignContact.node_ids" + entry + " = " + std::to_string(node) +
          " is not a node of the contact boundary (see InterfaceDescription.node_ids)");
    }
    if (contact.components[k] < 0 || contact.components[k] >= dimension) {
      throw InputError(
          context + ": AssignContact.components" + entry + " = " +
          std::to_string(contact.components[k]) +
          (dimension == 3 ? ", expected 0 (x), 1 (y) or 2 (z)" : ", expected 0 (x) or 1 (y)"));
    }
    if (!std::isfinite(contact.values[k])) {
      throw InputError(context + ": AssignContact.values" + entry + " is not a finite number");
    }
    seen.emplace_back(node, contact.components[k]);
  }
  std::sort(seen.begin(), seen.end());
  const auto repeated = std::adjacent_find(seen.begin(), seen.end());
  if (repeated != seen.end()) {
    throw InputError(context + ": AssignContact constraint " + std::to_string(row) +
                     " names component " + std::to_string(repeated->second) + " of node id " +
                     std::to_string(repeated->first) +
                     " twice (each (node, component) at most once per row)");
  }
  const double weight = contact.weights[row];
  if (!std::isfinite(weight) || weight <= 0.0) {
    throw InputError(context + ": AssignContact.weights[" + std::to_string(row) +
                     "] is not a finite positive number");
  }
}

}  // namespace

void check_contact_operator(const ContactOperator& contact, const std::vector<int>& contact_nodes,
                            int dimension, const std::string& context) {
  if (contact.nodes.size() != contact.values.size() ||
      contact.components.size() != contact.values.size()) {
    throw InputError(context + ": AssignContact has " + std::to_string(contact.nodes.size()) +
                     " node_ids, " + std::to_string(contact.components.size()) +
                     " components and " + std::to_string(contact.values.size()) +
                     " values: expected one of each per entry");
  }
  check_offsets(contact, context);
  if (contact.weights.size() != static_cast<std::size_t>(contact.row_count())) {
    throw InputError(context + ": AssignContact.weights has " +
                     std::to_string(contact.weights.size()) + " values for " +
                     std::to_string(contact.row_count()) + " constraints");
  }
  for (int row = 0; row < contact.row_count(); ++row)
    check_row(contact, row, contact_nodes, dimension, context);
}

}  // namespace robin
