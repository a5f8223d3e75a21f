// libFuzzer target for what fieldguard hears as a J1939 node: any sequence of CAN frames (with the time between
// them) into the node (address claim, requests, violations, BAM pacing) and into a BAM receiver, and any bytes as
// a DM1/DM2. Traps on a broken invariant: a frame out of range, a frame from an address we do not hold, a
// diagnostic message that does not survive encode and decode.
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fieldguard/output/j1939.hpp"
#include "fieldguard/output/j1939_node.hpp"

namespace {

using namespace fieldguard::output;
using namespace fieldguard::output::j1939;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

void check_out(const Node& n, const std::vector<CanFrame>& out) {
  for (const auto& f : out) {
    check(f.len <= 8 && f.id <= kEffMask);
    const auto src = static_cast<std::uint8_t>(f.id & 0xFFU);
    const bool claim = j1939_fields(f.id).pgn == kPgnAddressClaimed;
    // Every frame from the address we hold; only a claim (or Cannot Claim, from the null address) otherwise.
    if (!claim) check(n.claimer().address() && src == *n.claimer().address());
    if (claim && src == kNullAddress) check(n.claimer().state() == ClaimState::CannotClaim);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> in(data, size);
  if (auto d = decode_diagnostic(in)) {
    const auto again = decode_diagnostic(encode_diagnostic(*d));
    check(again.has_value() && again->dtcs == d->dtcs && again->lamps == d->lamps);
  }

  NodeParams p;
  p.claim.name.identity_number = 1;
  p.claim.name.arbitrary_address_capable = size > 0 && (data[0] & 1U) != 0;
  p.claim.preferred_address = size > 1 ? static_cast<std::uint8_t>(data[1] % 0xFE) : 0x80;
  Node node(p);
  BamReceiver bam;
  std::vector<CanFrame> out;
  double t = 0.0;
  node.start(t, out);
  check_out(node, out);
  constexpr std::size_t kRecord = 14;  // id 4, len 1, data 8, time step 1
  for (std::size_t at = 2; at + kRecord <= size; at += kRecord) {
    CanFrame f;
    f.id = (std::uint32_t{data[at]} | std::uint32_t{data[at + 1]} << 8U | std::uint32_t{data[at + 2]} << 16U |
            std::uint32_t{data[at + 3]} << 24U) &
           kEffMask;
    f.len = static_cast<std::uint8_t>(data[at + 4] % 9);
    for (std::size_t i = 0; i < 8; ++i) f.data[i] = data[at + 5 + i];
    t += static_cast<double>(data[at + 13]) * 0.01;
    // Each call's frames checked against the address right after it: a later frame may move it.
    out.clear();
    node.tick(t, out);
    check_out(node, out);
    out.clear();
    node.receive(f, t, out);
    check_out(node, out);
    if ((data[at + 4] & 0x80U) != 0) {
      DiagnosticMessage m;
      m.dtcs.push_back(Dtc{f.id & 0x7FFFFU, static_cast<std::uint8_t>(f.data[0] & 0x1FU), 1});
      out.clear();
      node.set_dm1(m, t, out);
      check_out(node, out);
    }
    if (auto m = bam.feed(f, t)) check(m->data.size() >= 9 && m->data.size() <= kMaxTransportBytes);
  }
  return 0;
}
