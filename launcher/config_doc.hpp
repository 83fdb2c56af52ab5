// The configuration reference (docs/configuration.md): every section's keys, types, defaults,
// units and docs, rendered from the tables that read them (common/config/table.hpp).
#pragma once

#include <string>

namespace auvrl::launcher {

/// docs/configuration.md as `auvrl config-doc` prints it: the run file's sections, then the
/// vehicle file's blocks, the PID gains file and the mission file.
std::string configuration_reference();

}  // namespace auvrl::launcher
