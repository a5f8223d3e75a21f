#pragma once
// The DBC of the messages we send, printed from the layouts (can_layout.hpp) for the given addressing.
// config/fieldguard.dbc is this text for the default CanParams; a test keeps the two equal.

#include <string>

#include "fieldguard/output/can_encoder.hpp"

namespace fieldguard::output {

[[nodiscard]] std::string dbc_text(const CanParams& params);

}  // namespace fieldguard::output
