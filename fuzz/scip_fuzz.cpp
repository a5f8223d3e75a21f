// libFuzzer target for the SCIP 2.0 client side: the reply parser (whole input and the same input in chunks must
// give the same replies and counters), the scan / VV / PP / II decoders, 2D points and the client state machine.
// Traps on any broken output invariant.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/drivers/scip.hpp"
#include "fieldguard/drivers/scip_client.hpp"
#include "fieldguard/drivers/scip_data.hpp"

namespace {

using namespace fieldguard;
using namespace fieldguard::scip;

void check(bool ok) {
  if (!ok) __builtin_trap();
}

bool same(const Reply& a, const Reply& b) {
  return a.echo == b.echo && a.command == b.command && a.status == b.status && a.category == b.category &&
         a.lines == b.lines;
}

void check_reply(const Reply& r) {
  check(r.command != Command::Unknown);
  check(command_of_echo(r.echo) == r.command);
  check(classify_status(r.status) == r.category);
  for (const auto& l : r.lines) check(!l.empty() && l.size() < kMaxLineLength);

  const auto scan = decode_scan(r);
  if (scan) {
    check(scan->last_step >= scan->first_step && scan->cluster >= 1);
    const std::size_t n = scan->ranges_mm.size();
    const std::size_t steps = static_cast<std::size_t>(scan->last_step - scan->first_step) + 1;
    check(n == values_in_scan(scan->first_step, scan->last_step, scan->cluster) || n == steps / scan->cluster);
    check(scan->intensities.empty() || scan->intensities.size() == n);
    check(scan->timestamp_ms < (1U << 24));
    for (const auto v : scan->ranges_mm) check(v < (1U << 18));
    std::vector<Point2> pts;
    scan_to_points(*scan, Geometry{}, pts);
    check(pts.size() <= n);
    for (const auto& p : pts) {
      check(std::isfinite(p.x_m) && std::isfinite(p.y_m));
      check(p.range_m >= 0.023F - 1e-6F && p.range_m <= 60.F + 1e-3F);
    }
  }
  const auto info = decode_info(r);
  if (info) check(info->size() <= r.lines.size());
  const auto pp = decode_parameters(r);
  if (pp) check(pp->ares > 0 && pp->amin <= pp->afrt && pp->afrt <= pp->amax);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);  // NOLINT

  ReplyParser whole;
  std::vector<Reply> a;
  whole.push(input, a);

  // The same bytes in chunks whose sizes come from the input itself.
  ReplyParser chunked;
  std::vector<Reply> b;
  for (std::size_t i = 0, k = 0; i < size; ++k) {
    const std::size_t n = std::min<std::size_t>(size - i, 1 + (data[k % size] % 97));
    chunked.push(input.substr(i, n), b);
    i += n;
  }
  check(a.size() == b.size());
  for (std::size_t i = 0; i < a.size(); ++i) check(same(a[i], b[i]));
  check(whole.counters().errors == chunked.counters().errors);
  check(whole.counters().discarded_bytes == chunked.counters().discarded_bytes);
  check(whole.counters().replies == a.size());
  check(whole.counters().discarded_bytes <= size);

  for (const auto& r : a) check_reply(r);

  // The client, started and fed every reply; stop and reset on the way.
  Client client;
  (void)client.start();
  std::size_t k = 0;
  for (const auto& r : a) {
    const ClientEvent e = client.on_reply(r);
    check(!(e.scan && e.refused));
    if (e.refused) check(client.state() == ClientState::Failed);
    if (++k == a.size() / 2 && size > 0 && (data[0] & 1) != 0) (void)client.stop();
  }
  const auto& c = client.counters();
  check(c.replies == a.size());
  check(c.scans <= c.replies);

  // Encodings on slices of the input.
  for (std::size_t w = 1; w <= 4 && w <= size; ++w) {
    const auto v = decode_chars(input.substr(0, w));
    if (v) {
      std::string s;
      encode_chars(*v, w, s);
      check(s == input.substr(0, w));
    }
  }
  return 0;
}
