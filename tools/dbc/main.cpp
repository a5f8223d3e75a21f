// fieldguard-dbc: prints the DBC of the CAN messages fieldguard sends, from the layouts in
// src/output/can_layout.cpp. `fieldguard-dbc > config/fieldguard.dbc` regenerates the shipped file (a test
// fails while the two differ); the address options print the DBC for another tractor's bus.

#include <charconv>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string_view>

#include "cli/cli.hpp"
#include "fieldguard/output/dbc.hpp"

namespace {

namespace cli = fieldguard::tools::cli;

// A J1939 address: 0..255, decimal or 0x hex.
bool parse_address(std::string_view s, std::uint8_t& out) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);
    base = 16;
  }
  unsigned v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (s.empty() || r.ec != std::errc{} || r.ptr != s.data() + s.size() || v > 0xFF) return false;
  out = static_cast<std::uint8_t>(v);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  fieldguard::output::CanParams p;
  cli::Tool tool("fieldguard-dbc", "fieldguard-dbc [--source-address A] [--controller-address A]",
                 "Prints the DBC of fieldguard's CAN messages (addresses decimal or 0x hex; defaults 0x80 and 0x26).",
                 "`fieldguard-dbc > config/fieldguard.dbc` regenerates the shipped file; the address options print\n"
                 "the DBC for another tractor's bus.\n"
                 "Exit codes: 0 printed; 1 writing failed; 2 bad command line or addresses.");
  CLI::App& app = tool.app();
  const auto any = [](std::uint8_t /*address*/) { return true; };
  const std::string address = "an address 0..255 (decimal or 0x hex)";
  cli::checked(app, "--source-address", p.source_address, parse_address, any, address,
               "fieldguard's own source address on the bus (default 0x80)")
      ->type_name("A");
  cli::checked(app, "--controller-address", p.controller_address, parse_address, any, address,
               "the steering controller's address the stop request goes to (default 0x26)")
      ->type_name("A");
  if (const auto exit_code = tool.parse(argc, argv)) return *exit_code;
  if (const auto problems = fieldguard::output::validate(p); !problems.empty()) {
    for (const auto& s : problems) std::cerr << "fieldguard-dbc: " << s << "\n";
    return cli::kExitBadCommandLine;
  }
  try {
    std::cout << fieldguard::output::dbc_text(p);
  } catch (const std::exception& e) {
    std::cerr << "fieldguard-dbc: " << e.what() << "\n";
    return 1;
  }
  std::cout.flush();
  return std::cout ? 0 : 1;
}
