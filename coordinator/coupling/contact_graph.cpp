#include "coupling/contact_graph.hpp"

#include <deque>

#include "numerics/errors.hpp"

namespace robin {

ContactGraph::ContactGraph(int body_count, const std::vector<Edge>& edges)
    : body_count_(body_count), body_rows_(static_cast<std::size_t>(std::max(body_count, 0)), 0) {
  if (body_count < 1) throw InputError("a contact graph needs at least one body");
  for (std::size_t k = 0; k < edges.size(); ++k) {
    const Edge& edge = edges[k];
    const std::string name = "contact interface " + std::to_string(k + 1);
    if (edge.body_a < 0 || edge.body_a >= body_count || edge.body_b < 0 ||
        edge.body_b >= body_count) {
      throw InputError(name + " names a body outside 1.." + std::to_string(body_count));
    }
    if (edge.body_a == edge.body_b) {
      throw InputError(name + " joins body " + std::to_string(edge.body_a + 1) + " to itself");
    }
    if (edge.rows < 0) throw InputError(name + " has a negative number of rows");
    GraphInterface interface;
    interface.body_a = edge.body_a;
    interface.body_b = edge.body_b;
    interface.rows = edge.rows;
    interface.global_offset = total_rows_;
    interface.offset_a = body_rows_[static_cast<std::size_t>(edge.body_a)];
    interface.offset_b = body_rows_[static_cast<std::size_t>(edge.body_b)];
    body_rows_[static_cast<std::size_t>(edge.body_a)] += edge.rows;
    body_rows_[static_cast<std::size_t>(edge.body_b)] += edge.rows;
    total_rows_ += edge.rows;
    interfaces_.push_back(interface);
  }
}

ContactGraph ContactGraph::two_bodies(Eigen::Index rows) {
  return ContactGraph(2, {{0, 1, rows}});
}

Eigen::VectorXd ContactGraph::body_part(int body, const Eigen::VectorXd& global) const {
  Eigen::VectorXd part(body_rows(body));
  for (const GraphInterface& interface : interfaces_) {
    const auto rows = global.segment(interface.global_offset, interface.rows);
    if (interface.body_a == body) part.segment(interface.offset_a, interface.rows) = rows;
    if (interface.body_b == body) part.segment(interface.offset_b, interface.rows) = rows;
  }
  return part;
}

void ContactGraph::add_body_part(int body, const Eigen::VectorXd& part,
                                 Eigen::VectorXd& global) const {
  for (const GraphInterface& interface : interfaces_) {
    auto rows = global.segment(interface.global_offset, interface.rows);
    if (interface.body_a == body) rows += part.segment(interface.offset_a, interface.rows);
    if (interface.body_b == body) rows += part.segment(interface.offset_b, interface.rows);
  }
}

Eigen::VectorXd ContactGraph::across(int body, const std::vector<Eigen::VectorXd>& per_body) const {
  Eigen::VectorXd values(body_rows(body));
  for (const GraphInterface& interface : interfaces_) {
    const auto& from_a = per_body[static_cast<std::size_t>(interface.body_a)];
    const auto& from_b = per_body[static_cast<std::size_t>(interface.body_b)];
    if (interface.body_a == body) {
      values.segment(interface.offset_a, interface.rows) =
          from_b.segment(interface.offset_b, interface.rows);
    }
    if (interface.body_b == body) {
      values.segment(interface.offset_b, interface.rows) =
          from_a.segment(interface.offset_a, interface.rows);
    }
  }
  return values;
}

Eigen::VectorXd ContactGraph::side(int side, const std::vector<Eigen::VectorXd>& per_body) const {
  Eigen::VectorXd values(total_rows_);
  for (const GraphInterface& interface : interfaces_) {
    const int body = side == 0 ? interface.body_a : interface.body_b;
    const Eigen::Index offset = side == 0 ? interface.offset_a : interface.offset_b;
    values.segment(interface.global_offset, interface.rows) =
        per_body[static_cast<std::size_t>(body)].segment(offset, interface.rows);
  }
  return values;
}

int ContactGraph::body_of_row(Eigen::Index row, int side) const {
  for (const GraphInterface& interface : interfaces_) {
    if (row >= interface.global_offset && row < interface.global_offset + interface.rows) {
      return side == 0 ? interface.body_a : interface.body_b;
    }
  }
  throw InputError("row " + std::to_string(row) + " is outside the contact graph's " +
                   std::to_string(total_rows_) + " rows");
}

std::optional<std::vector<int>> ContactGraph::two_colouring() const {
  std::vector<int> colour(static_cast<std::size_t>(body_count_), -1);
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(body_count_));
  for (const GraphInterface& interface : interfaces_) {
    neighbours[static_cast<std::size_t>(interface.body_a)].push_back(interface.body_b);
    neighbours[static_cast<std::size_t>(interface.body_b)].push_back(interface.body_a);
  }
  for (int start = 0; start < body_count_; ++start) {
    if (colour[static_cast<std::size_t>(start)] >= 0) continue;
    colour[static_cast<std::size_t>(start)] = 0;
    std::deque<int> queue{start};
    while (!queue.empty()) {
      const int body = queue.front();
      queue.pop_front();
      for (const int neighbour : neighbours[static_cast<std::size_t>(body)]) {
        int& other = colour[static_cast<std::size_t>(neighbour)];
        if (other < 0) {
          other = 1 - colour[static_cast<std::size_t>(body)];
          queue.push_back(neighbour);
        } else if (other == colour[static_cast<std::size_t>(body)]) {
          return std::nullopt;
        }
      }
    }
  }
  return colour;
}

std::vector<int> ContactGraph::components() const {
  std::vector<int> component(static_cast<std::size_t>(body_count_), -1);
  std::vector<std::vector<int>> neighbours(static_cast<std::size_t>(body_count_));
  for (const GraphInterface& interface : interfaces_) {
    neighbours[static_cast<std::size_t>(interface.body_a)].push_back(interface.body_b);
    neighbours[static_cast<std::size_t>(interface.body_b)].push_back(interface.body_a);
  }
  int count = 0;
  for (int start = 0; start < body_count_; ++start) {
    if (component[static_cast<std::size_t>(start)] >= 0) continue;
    component[static_cast<std::size_t>(start)] = count;
    std::deque<int> queue{start};
    while (!queue.empty()) {
      const int body = queue.front();
      queue.pop_front();
      for (const int neighbour : neighbours[static_cast<std::size_t>(body)]) {
        if (component[static_cast<std::size_t>(neighbour)] >= 0) continue;
        component[static_cast<std::size_t>(neighbour)] = count;
        queue.push_back(neighbour);
      }
    }
    ++count;
  }
  return component;
}

ContactOperator stack_operators(const std::vector<const ContactOperator*>& parts) {
  ContactOperator stacked;
  for (const ContactOperator* part : parts) {
    for (int row = 0; row < part->row_count(); ++row) {
      for (std::size_t entry = part->row_offsets[static_cast<std::size_t>(row)];
           entry < part->row_offsets[static_cast<std::size_t>(row) + 1]; ++entry) {
        stacked.add_entry(part->nodes[entry], part->components[entry], part->values[entry]);
      }
      stacked.finish_row(part->weights[static_cast<std::size_t>(row)]);
    }
  }
  return stacked;
}

Eigen::VectorXd concatenate(const std::vector<Eigen::VectorXd>& parts) {
  Eigen::Index size = 0;
  for (const Eigen::VectorXd& part : parts) size += part.size();
  Eigen::VectorXd values(size);
  Eigen::Index offset = 0;
  for (const Eigen::VectorXd& part : parts) {
    values.segment(offset, part.size()) = part;
    offset += part.size();
  }
  return values;
}

std::string describe_bodies(const std::vector<int>& bodies) {
  if (bodies.size() == 1) return "body " + std::to_string(bodies.front() + 1);
  std::string text = "bodies ";
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    if (k > 0) text += k + 1 == bodies.size() ? " and " : ", ";
    text += std::to_string(bodies[k] + 1);
  }
  return text;
}

}  // namespace robin
