#pragma once
// A CAN sink that keeps every frame with its stamp, for the output stage's and the link's tests.

#include <span>
#include <vector>

#include "fieldguard/core/time.hpp"
#include "fieldguard/output/can_sink.hpp"

namespace fieldguard::testing {

struct Sent {
  output::CanFrame frame;
  Stamp t;
};

class RecordingSink final : public output::CanSink {
 public:
  void write(std::span<const output::CanFrame> frames, Stamp t) override {
    for (const auto& f : frames) sent.push_back({f, t});
    stats_.sent += frames.size();
  }
  [[nodiscard]] const output::CanSinkStats& stats() const override { return stats_; }
  std::vector<Sent> sent;

 private:
  output::CanSinkStats stats_;
};

}  // namespace fieldguard::testing
