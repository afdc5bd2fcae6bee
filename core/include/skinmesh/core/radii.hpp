// Van der Waals radii by element: A. Bondi, "van der Waals Volumes and Radii",
// J. Phys. Chem. 68 (1964) 441-451, Table I (the values most molecular-surface
// tools use). Elements Bondi did not tabulate (Fe, Ca, Mn, ...) are "unknown".
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace skinmesh {

// Radius in Angstrom for an upper- or mixed-case element symbol, or nothing.
std::optional<double> bondi_radius(const std::string& element);

// The whole table, for documentation and reports: (symbol, radius in Angstrom).
const std::vector<std::pair<std::string, double>>& bondi_table();

}  // namespace skinmesh
