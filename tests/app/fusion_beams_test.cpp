// The 3D LiDAR's rings reach the workers with each frame: SensorFusion gives every job the ring geometry of the
// sensor it came from (its decoder's table), and a FrameDetector's pipeline takes it.
#include <gtest/gtest.h>

#include <memory>
#include <string>
#include <vector>

#include "app/sim_can_support.hpp"
#include "fieldguard/config/config.hpp"
#include "fieldguard/drivers/lidar3d_stream.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/io/pcap_reader.hpp"

namespace fieldguard::app {
namespace {

const std::string kSource = FIELDGUARD_SOURCE_DIR;

std::vector<FrameJob> jobs_of(const Config& cfg, const std::string& pcap) {
  SensorFusion fusion(cfg, {});
  auto reader = io::PcapReader::open(pcap);
  EXPECT_TRUE(reader.has_value()) << pcap;
  std::vector<FrameJob> jobs;
  Stamp last;
  if (!reader) return jobs;
  while (auto d = reader->next()) {
    last = d->host_time;
    if (const auto ch = fusion.stream().channel_of(d->dst_port)) fusion.lidar(*ch, d->payload, d->host_time, jobs);
  }
  fusion.finish(last, jobs);
  return jobs;
}

Config shipped() {
  auto r = load_config_file(kSource + "/config/fieldguard.yaml");
  EXPECT_TRUE(r.ok());
  return r.config;
}

TEST(FusionBeams, EveryJobCarriesItsSensorsRings) {
  const Config cfg = shipped();
  testing::PedestrianCapture rs32(4, "rs32");
  ASSERT_TRUE(rs32.ok) << rs32.command;
  const auto rs_jobs = jobs_of(cfg, rs32.pcap);
  ASSERT_GE(rs_jobs.size(), 4U);
  for (const FrameJob& j : rs_jobs) {
    ASSERT_TRUE(j.beams) << "a job without the sensor's rings";
    EXPECT_FALSE(j.beams->is_uniform());
    EXPECT_EQ(j.beams->rings(), 32U);
    EXPECT_EQ(j.beams.get(), rs_jobs.front().beams.get()) << "the geometry is made once, not per frame";
  }
  EXPECT_NEAR(rs_jobs.front().beams->max_spacing_deg(), 10.36, 1e-9);

  const auto hdl_jobs = jobs_of(cfg, std::string(FIELDGUARD_TEST_DATA) + "/hdl32e_monterey_600.pcap");
  ASSERT_FALSE(hdl_jobs.empty());
  for (const FrameJob& j : hdl_jobs) {
    ASSERT_TRUE(j.beams);
    EXPECT_TRUE(j.beams->is_uniform());
    EXPECT_NEAR(j.beams->spacing_deg(0.0), 1.33, 0.005);
  }
  // A worker's pipeline takes the rings with the job (the configuration leaves the spacing to the sensor).
  FrameDetector detector(cfg);
  FrameJob job = rs_jobs[1];
  DetectedFrame d;
  detector.process(job, d);
  EXPECT_EQ(detector.pipeline().beams(), *rs_jobs[1].beams);
}

}  // namespace
}  // namespace fieldguard::app
