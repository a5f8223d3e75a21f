#pragma once
// Processed frames into MCAP files on one timeline (each message's log time is its frame's time), on the
// channels of frame_messages.hpp. One file, or (live, where a recording must not fill the disk) a series of
// files of a bounded size of which the newest few are kept: PATH's stem + _NNNN + its extension, each a whole
// MCAP file that starts at a frame. Thread-compatible: one thread records.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fieldguard/config/config.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/writers/frame_messages.hpp"
#include "fieldguard/writers/mcap_writer.hpp"

namespace fieldguard::app {

struct McapRecording {
  std::string path;
  McapOptions options;
  std::uint64_t max_bytes = 0;  // 0: one file at `path`, however large; else a new file once one is this large
  int max_files = 0;            // with max_bytes: the newest this many files are kept (0: every one)
};

struct McapRecorderStats {
  std::uint64_t frames = 0;
  std::uint64_t messages = 0;
  std::uint64_t bytes = 0;    // written, every file
  std::uint64_t files = 0;    // opened
  std::uint64_t removed = 0;  // old files removed to keep max_files
};

class McapRecorder {
 public:
  explicit McapRecorder(const Config& cfg);

  // Opens the (first) file and writes the schemas and channels. False with error() set when it cannot.
  bool open(const McapRecording& recording);
  // One frame (FrameEncoder::encode). False with error() set when a file cannot be written; nothing more is
  // written then.
  bool frame(const LidarFrame& frame, const perception::FrameResult& result,
             std::span<const perception::LabeledPoint> points, const FusionInfo* fusion,
             const output::safety::Decision* decision);
  // The same in two steps, for a caller that encodes the frame itself (and sends its messages elsewhere too):
  // begin_frame() (a bounded recording may start its next file here), then each message of the frame.
  bool begin_frame();
  void message(Topic topic, std::int64_t stamp_ns, std::string_view json);
  // The summary and footer of the file being written.
  bool close();

  [[nodiscard]] const std::string& error() const { return error_; }
  [[nodiscard]] McapRecorderStats stats() const;
  // The file being written (or the last one).
  [[nodiscard]] const std::string& current_path() const { return current_; }
  // The name of the `index`th file of a bounded recording (from 1).
  [[nodiscard]] static std::string numbered(const std::string& path, std::uint64_t index);

 private:
  bool open_next();

  FrameEncoder encoder_;
  McapRecording rec_;
  std::unique_ptr<McapWriter> writer_;
  std::vector<std::uint16_t> channels_;  // by Topic
  std::string error_;
  std::string current_;
  McapRecorderStats done_;  // of the files closed
  std::uint64_t frames_ = 0;
};

}  // namespace fieldguard::app
