#include "coupling/contact_discretization.hpp"

#include "numerics/errors.hpp"

namespace robin {
namespace {

MortarOptions mortar_options(const ContactOptions& options, const std::string& name1,
                             const std::string& name2, MortarIntegration integration) {
  MortarOptions mortar;
  mortar.integration = integration;
  if (options.non_mortar.empty()) return mortar;
  if (options.non_mortar == name1) {
    mortar.non_mortar_body = 0;
  } else if (options.non_mortar == name2) {
    mortar.non_mortar_body = 1;
  } else {
    throw InputError("contact.non_mortar: '" + options.non_mortar +
                     "' is not a body (the bodies are '" + name1 + "' and '" + name2 + "')");
  }
  return mortar;
}

}  // namespace

ContactPairing discretize_contact(const InterfaceDescription& body1, const std::string& name1,
                                  const InterfaceDescription& body2, const std::string& name2,
                                  const GapFunction* gap, const ContactOptions& options,
                                  double pairing_tolerance) {
  switch (options.method) {
    case ContactMethod::node_to_node:
      return pair_contact_nodes(body1, name1, body2, name2, gap, pairing_tolerance);
    case ContactMethod::mortar:
      return build_mortar_coupling(
          body1, name1, body2, name2, gap,
          mortar_options(options, name1, name2, MortarIntegration::segment_to_segment));
    case ContactMethod::node_to_segment:
      return build_mortar_coupling(
          body1, name1, body2, name2, gap,
          mortar_options(options, name1, name2, MortarIntegration::node_to_segment));
    case ContactMethod::automatic:
      break;
  }
  try {
    return pair_contact_nodes(body1, name1, body2, name2, gap, pairing_tolerance);
  } catch (const UnmatchedContactNodes&) {
    return build_mortar_coupling(
        body1, name1, body2, name2, gap,
        mortar_options(options, name1, name2, MortarIntegration::segment_to_segment));
  }
}

std::string describe_contact(const ContactPairing& pairing, const std::string& name1,
                             const std::string& name2) {
  if (pairing.non_mortar_body < 0) {
    return "node-to-node pairing, " + std::to_string(pairing.size()) + " contact pairs (" +
           std::to_string(pairing.excluded.size()) + " excluded)";
  }
  const std::string& nonmortar = pairing.non_mortar_body == 0 ? name1 : name2;
  const std::string& mortar = pairing.non_mortar_body == 0 ? name2 : name1;
  std::string text = "mortar coupling (non-mortar side: body '" + nonmortar + "'), " +
                     std::to_string(pairing.size()) + " constraints (" +
                     std::to_string(pairing.excluded.size()) + " excluded)";
  if (pairing.uncovered > 0) {
    text += "; " + std::to_string(pairing.uncovered) + " contact nodes of body '" + nonmortar +
            "' face no part of body '" + mortar + "' and carry no constraint";
  }
  return text;
}

}  // namespace robin
