// SCIP 2.0 VV / PP / II replies: "LABEL:value;" lines to a map, and PP to typed parameters.
#include <charconv>

#include "fieldguard/drivers/scip_data.hpp"

namespace fieldguard::scip {

namespace {

std::optional<std::uint32_t> decimal(std::string_view s) {
  std::uint32_t v = 0;
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, v);
  if (s.empty() || ec != std::errc{} || ptr != end) return std::nullopt;
  return v;
}

}  // namespace

Expected<InfoMap, Error> decode_info(const Reply& reply) {
  const bool info = reply.command == Command::VV || reply.command == Command::PP || reply.command == Command::II;
  if (!info || reply.status != "00") return Unexpected{Error::NotThisReply};
  InfoMap m;
  for (std::string_view line : reply.lines) {
    if (!line.empty() && line.back() == ';') line.remove_suffix(1);
    const std::size_t colon = line.find(':');
    if (colon == std::string_view::npos || colon == 0) return Unexpected{Error::BadField};
    m.insert_or_assign(std::string(line.substr(0, colon)), std::string(line.substr(colon + 1)));
  }
  return m;
}

Expected<Parameters, Error> decode_parameters(const Reply& reply) {
  if (reply.command != Command::PP) return Unexpected{Error::NotThisReply};
  auto info = decode_info(reply);
  if (!info) return Unexpected{info.error()};
  Parameters p;
  const auto field = [&](std::string_view key, std::uint32_t& out) {
    const auto it = info->find(key);
    if (it == info->end()) return false;
    const auto v = decimal(it->second);
    if (!v) return false;
    out = *v;
    return true;
  };
  if (!field("DMIN", p.dmin_mm) || !field("DMAX", p.dmax_mm) || !field("ARES", p.ares) || !field("AMIN", p.amin) ||
      !field("AMAX", p.amax) || !field("AFRT", p.afrt) || !field("SCAN", p.scan_rpm)) {
    return Unexpected{Error::BadField};
  }
  if (p.ares == 0 || p.amin > p.afrt || p.afrt > p.amax || p.dmin_mm > p.dmax_mm) return Unexpected{Error::BadField};
  if (const auto it = info->find("MODL"); it != info->end()) p.model = it->second;
  return p;
}

}  // namespace fieldguard::scip
