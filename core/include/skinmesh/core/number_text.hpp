// Doubles as text that reads back to the same double (17 significant digits),
// for every text format skinmesh writes: a vertex exactly on the skin stays on
// it in the file.
#pragma once

#include <string>

namespace skinmesh {

std::string exact_number_text(double value);

}  // namespace skinmesh
