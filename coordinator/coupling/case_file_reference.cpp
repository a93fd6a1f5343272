#include "coupling/case_file_reference.hpp"

#include <cmath>
#include <numbers>
#include <vector>

#include "coupling/case_file_body.hpp"
#include "coupling/case_file_table.hpp"

namespace robin {

namespace {

const std::vector<std::string> reference_keys{
    "kind", "load", "radius", "contact_modulus", "center", "model_fraction"};

/// The value of `key` checked to be > 0, or nullopt when absent.
std::optional<double> optional_positive(const CheckedTable& table, std::string_view key) {
  const auto value = table.optional_number(key);
  if (value && !(*value > 0.0)) {
    table.fail(key, "must be > 0, got " + format_number(*value));
  }
  return value;
}

/// 1/E* = sum over both bodies of 1/E', E' = E/(1 - nu^2) (plane strain and solid bodies) or E
/// (plane stress), from the [[body]] tables (already validated by the body reader).
double contact_modulus_of_bodies(const CheckedTable& root, const CheckedTable& reference) {
  double compliance = 0.0;
  for (const TableEntry& entry : root.array_of_tables("body")) {
    const toml::node_view<const toml::node> body(*entry.table);
    const auto young = body["material"]["young"].value<double>();
    const auto poisson = body["material"]["poisson"].value<double>();
    if (!young || !poisson) {
      reference.fail("contact_modulus",
                     "missing: " + entry.path +
                         " has no isotropic material (young, poisson), "
                         "so the default 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2 does not apply");
    }
    const bool plane_stress = body["model"].value_or(std::string()) == "plane_stress";
    compliance += (plane_stress ? 1.0 : 1.0 - *poisson * *poisson) / *young;
  }
  return 1.0 / compliance;
}

}  // namespace

std::optional<ReferenceSolution> read_reference(const CheckedTable& root, int dimension) {
  const auto table = root.optional_table("reference", reference_keys);
  if (!table) return std::nullopt;
  ReferenceSolution reference;
  reference.location = table->location("");
  const std::string kind = dimension == 3 ? "hertz_sphere" : "hertz_cylinder";
  if (!table->contains("kind")) table->fail("kind", "missing required key (\"" + kind + "\")");
  const std::string given = *table->optional_choice("kind", {"hertz_cylinder", "hertz_sphere"});
  if (given != kind) {
    table->fail("kind", "\"" + given + "\" is the reference of " +
                            (dimension == 3 ? "plane" : "solid") +
                            " bodies; a case with dimension = " + std::to_string(dimension) +
                            " takes \"" + kind + "\"");
  }
  reference.kind =
      given == "hertz_sphere" ? ReferenceKind::hertz_sphere : ReferenceKind::hertz_cylinder;
  reference.load = optional_positive(*table, "load");
  reference.radius = table->number("radius");  // required
  if (!(reference.radius > 0.0)) {
    table->fail("radius", "must be > 0, got " + format_number(reference.radius));
  }
  const auto modulus = optional_positive(*table, "contact_modulus");
  reference.contact_modulus_given = modulus.has_value();
  reference.contact_modulus = modulus ? *modulus : contact_modulus_of_bodies(root, *table);
  if (const auto fraction = table->optional_number("model_fraction")) {
    if (!(*fraction > 0.0 && *fraction <= 1.0)) {
      table->fail("model_fraction", "must be in (0, 1], got " + format_number(*fraction));
    }
    reference.model_fraction = *fraction;
  }
  if (const auto center = table->optional_vector("center", dimension)) {
    reference.center = Eigen::Vector3d::Zero();
    reference.center->head(dimension) = *center;
  }
  return reference;
}

double hertz_contact_radius(const ReferenceSolution& reference, double load) {
  return std::cbrt(3.0 * load * reference.radius / (4.0 * reference.contact_modulus));
}

double hertz_sphere_peak_pressure(const ReferenceSolution& reference, double load) {
  const double radius = hertz_contact_radius(reference, load);
  return 3.0 * load / (2.0 * std::numbers::pi * radius * radius);
}

double hertz_half_width(const ReferenceSolution& reference, double load) {
  return std::sqrt(4.0 * load * reference.radius / (std::numbers::pi * reference.contact_modulus));
}

double hertz_peak_pressure(const ReferenceSolution& reference, double load) {
  return 2.0 * load / (std::numbers::pi * hertz_half_width(reference, load));
}

}  // namespace robin
