// fieldguard-dbc: prints the DBC of the CAN messages fieldguard sends, from the layouts in
// src/output/can_layout.cpp. `fieldguard-dbc > config/fieldguard.dbc` regenerates the shipped file (a test
// fails while the two differ); the address options print the DBC for another tractor's bus.

#include <charconv>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string_view>

#include "fieldguard/output/dbc.hpp"

namespace {

bool parse_address(std::string_view s, std::uint8_t& out) {
  int base = 10;
  if (s.size() > 2 && s[0] == '0' && (s[1] == 'x' || s[1] == 'X')) {
    s.remove_prefix(2);
    base = 16;
  }
  unsigned v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (r.ec != std::errc{} || r.ptr != s.data() + s.size() || v > 0xFF) return false;
  out = static_cast<std::uint8_t>(v);
  return true;
}

int usage(int code) {
  (code == 0 ? std::cout : std::cerr)
      << "usage: fieldguard-dbc [--source-address A] [--controller-address A]\n"
         "Prints the DBC of fieldguard's CAN messages (addresses decimal or 0x hex; defaults 0x80 and 0x26).\n";
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  fieldguard::output::CanParams p;
  for (int i = 1; i < argc; ++i) {
    const std::string_view a = argv[i];
    if (a == "--help" || a == "-h") return usage(0);
    if ((a == "--source-address" || a == "--controller-address") && i + 1 < argc) {
      std::uint8_t v = 0;
      if (!parse_address(argv[++i], v)) {
        std::cerr << "fieldguard-dbc: " << a << ": not an address 0..255: " << argv[i] << "\n";
        return 2;
      }
      (a == "--source-address" ? p.source_address : p.controller_address) = v;
      continue;
    }
    std::cerr << "fieldguard-dbc: unknown argument " << a << "\n";
    return usage(2);
  }
  if (const auto problems = fieldguard::output::validate(p); !problems.empty()) {
    for (const auto& s : problems) std::cerr << "fieldguard-dbc: " << s << "\n";
    return 2;
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
