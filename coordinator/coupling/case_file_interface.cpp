#include "coupling/case_file_interface.hpp"

#include <algorithm>

#include "numerics/errors.hpp"

namespace robin {
namespace {

const std::vector<std::string> interface_keys{"bodies", "boundaries", "method", "non_mortar"};

/// The most contact boundaries one body may name (robin-subdomain's limit).
constexpr std::size_t maximum_contact_boundaries = 64;

std::string list_names(const std::vector<BodyCase>& bodies) {
  std::string names;
  for (const BodyCase& body : bodies) {
    names += (names.empty() ? "'" : ", '") + body.definition.name + "'";
  }
  return names;
}

int body_index(const CheckedTable& table, const std::vector<BodyCase>& bodies,
               const std::string& name) {
  for (std::size_t k = 0; k < bodies.size(); ++k) {
    if (bodies[k].definition.name == name) return static_cast<int>(k);
  }
  table.fail("bodies",
             "'" + name + "' is not the name of a body (the bodies: " + list_names(bodies) + ")");
}

ContactMethod method_of(const std::string& choice) {
  return choice == "node-to-node"      ? ContactMethod::node_to_node
         : choice == "mortar"          ? ContactMethod::mortar
         : choice == "node-to-segment" ? ContactMethod::node_to_segment
                                       : ContactMethod::automatic;
}

/// The coupling of one interface: its own method and non_mortar keys over the case's [contact];
/// a case-wide non_mortar body that is not on this interface leaves the choice to "auto".
std::optional<ContactOptions> interface_contact(const CheckedTable& table,
                                                const ContactOptions& defaults,
                                                const std::array<std::string, 2>& names) {
  const auto method =
      table.optional_choice("method", {"auto", "node-to-node", "mortar", "node-to-segment"});
  std::optional<std::string> non_mortar = table.optional_string("non_mortar");
  if (non_mortar && *non_mortar != "auto" && *non_mortar != names[0] && *non_mortar != names[1]) {
    table.fail("non_mortar", "'" + *non_mortar + "' is not one of the interface's bodies ('" +
                                 names[0] + "', '" + names[1] + "') nor \"auto\"");
  }
  const bool foreign_default = !defaults.non_mortar.empty() && defaults.non_mortar != names[0] &&
                               defaults.non_mortar != names[1];
  if (!method && !non_mortar && !foreign_default) return std::nullopt;
  ContactOptions contact = defaults;
  if (method) contact.method = method_of(*method);
  if (foreign_default) contact.non_mortar.clear();
  if (non_mortar) contact.non_mortar = *non_mortar == "auto" ? "" : *non_mortar;
  return contact;
}

/// Adds `boundary` to the body's contact boundaries (once) and records where the case names it.
void add_contact_boundary(BodyCase& body, const std::string& boundary,
                          const BoundaryReference& reference, const CheckedTable& table) {
  std::vector<std::string>& boundaries = body.definition.contact_boundaries;
  body.boundary_references.push_back(reference);
  if (std::find(boundaries.begin(), boundaries.end(), boundary) != boundaries.end()) return;
  if (boundaries.size() == maximum_contact_boundaries) {
    table.fail("boundaries", "body '" + body.definition.name + "' would have more than " +
                                 std::to_string(maximum_contact_boundaries) +
                                 " contact boundaries");
  }
  boundaries.push_back(boundary);
}

InterfaceCase read_interface(const TableEntry& entry, const CaseContext& context,
                             CaseDefinition& definition) {
  const CheckedTable table(*entry.table, entry.path, context, interface_keys);
  const std::array<std::string, 2> names = table.string_pair("bodies");
  const std::array<std::string, 2> boundaries = table.string_pair("boundaries");
  InterfaceCase result;
  InterfaceDefinition& interface = result.definition;
  interface.body_a = body_index(table, definition.bodies, names[0]);
  interface.body_b = body_index(table, definition.bodies, names[1]);
  if (interface.body_a == interface.body_b) {
    table.fail("bodies", "joins body '" + names[0] + "' to itself; an interface joins two bodies");
  }
  interface.boundary_a = boundaries[0];
  interface.boundary_b = boundaries[1];
  interface.contact = interface_contact(table, definition.contact, names);
  result.context = table.location("bodies") + ": " + entry.path;
  CaseContext file_only = context;
  file_only.body.clear();
  const std::string location = file_only.prefix(table.line("boundaries"));
  for (int side = 0; side < 2; ++side) {
    BodyCase& body =
        definition
            .bodies[static_cast<std::size_t>(side == 0 ? interface.body_a : interface.body_b)];
    const std::string field = table.field("boundaries") + "[" + std::to_string(side + 1) + "]";
    add_contact_boundary(body, boundaries[static_cast<std::size_t>(side)],
                         {boundaries[static_cast<std::size_t>(side)], field, location}, table);
  }
  return result;
}

bool same_interface(const InterfaceDefinition& first, const InterfaceDefinition& second) {
  const bool same_order = first.body_a == second.body_a && first.body_b == second.body_b &&
                          first.boundary_a == second.boundary_a &&
                          first.boundary_b == second.boundary_b;
  const bool swapped = first.body_a == second.body_b && first.body_b == second.body_a &&
                       first.boundary_a == second.boundary_b &&
                       first.boundary_b == second.boundary_a;
  return same_order || swapped;
}

}  // namespace

void read_interfaces(const CheckedTable& root, const std::vector<TableEntry>& bodies,
                     CaseDefinition& definition) {
  const std::vector<TableEntry> entries = root.array_of_tables("interface");
  if (entries.empty()) {  // two bodies, each with its contact_boundary (read with the body)
    InterfaceCase only;
    only.definition.boundary_a = definition.bodies[0].definition.contact_boundaries.at(0);
    only.definition.boundary_b = definition.bodies[1].definition.contact_boundaries.at(0);
    only.context = root.context().file;
    definition.interfaces.push_back(std::move(only));
    return;
  }
  for (const TableEntry& entry : entries) {
    definition.interfaces.push_back(read_interface(entry, root.context(), definition));
    const InterfaceCase& added = definition.interfaces.back();
    for (std::size_t k = 0; k + 1 < definition.interfaces.size(); ++k) {
      if (!same_interface(definition.interfaces[k].definition, added.definition)) continue;
      throw InputError(added.context + ": the same interface as interface[" +
                       std::to_string(k + 1) + "] (the same bodies and boundaries)");
    }
  }
  for (std::size_t alpha = 0; alpha < definition.bodies.size(); ++alpha) {
    if (!definition.bodies[alpha].definition.contact_boundaries.empty()) continue;
    CaseContext context = root.context();
    context.body = definition.bodies[alpha].definition.name;
    throw InputError(context.prefix(line_of(*bodies[alpha].table)) + ": body[" +
                     std::to_string(alpha + 1) +
                     "]: the body is in no [[interface]]; every body must touch another");
  }
}

}  // namespace robin
