#pragma once
// Live CAN input on the io thread's Boost.Asio io_context: a CAN_RAW socket (extended ids) that receives only
// the ids its filters let through, each frame handed over with its receive time. The daemon reads the tractor's
// speed with it (output/can_speed.hpp decodes it). Thread contract: construct, start() and stop() on the io
// thread (or before it runs); the handler runs on the io thread.

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldguard/core/expected.hpp"
#include "fieldguard/core/time.hpp"

namespace boost::asio {
class io_context;
}

namespace fieldguard::io {

// A frame passes when (id & mask) == (want & mask), over the 29-bit identifier of extended frames.
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
};

struct CanReaderStats {
  std::uint64_t frames = 0;    // handed to the handler
  std::uint64_t not_ours = 0;  // standard (11-bit), remote or error frames, or ids no filter passes
  std::uint64_t bad_size = 0;  // reads that were not one struct can_frame
  std::uint64_t errors = 0;    // receive errors other than would-block
};

class CanReader {
 public:
  // `id`: the 29-bit identifier; `data`: valid during the call only.
  using Handler = std::function<void(std::uint32_t id, std::span<const std::uint8_t> data, Stamp rx_time)>;

  // A CAN_RAW socket bound to `iface` with the kernel doing the filtering. The error says what failed and
  // what to do (no SocketCAN in the kernel, no such interface, ...).
  [[nodiscard]] static Expected<int, std::string> open_socket(std::string_view iface,
                                                              const std::vector<CanFilter>& filters);

  // Adopts `fd` (a CAN_RAW socket, or in tests one end of a socketpair carrying struct can_frame; the filters
  // are then applied here too) and closes it when destroyed.
  CanReader(boost::asio::io_context& io, int fd, std::vector<CanFilter> filters, Handler handler);
  ~CanReader();
  CanReader(const CanReader&) = delete;
  CanReader& operator=(const CanReader&) = delete;

  void start();
  void stop();  // idempotent

  [[nodiscard]] const CanReaderStats& stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldguard::io
