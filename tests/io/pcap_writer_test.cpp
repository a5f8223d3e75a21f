#include "fieldguard/io/pcap_writer.hpp"

#include <gtest/gtest.h>

#include "fieldguard/io/pcap_reader.hpp"
#include "io/pcap_builder.hpp"

namespace fieldguard::io {
namespace {

TEST(PcapWriter, WhatItWritesReadsBackExactly) {
  testing::TempDir dir;
  const auto path = (dir.path() / "rec.pcap").string();
  const testing::Bytes a = testing::pattern(1206, 3);
  const testing::Bytes b = testing::pattern(512, 9);
  {
    auto w = PcapWriter::create(path);
    ASSERT_TRUE(w.has_value()) << w.error();
    UdpDatagram d;
    d.host_time = Stamp{1'700'000'000'123'456'789};
    d.src_ip = testing::ipv4(192, 168, 1, 201);
    d.dst_ip = testing::ipv4(255, 255, 255, 255);
    d.src_port = 2368;
    d.dst_port = 2368;
    d.payload = a;
    EXPECT_TRUE(w->write(d));
    d.host_time = Stamp{1'700'000'001'000'000'001};
    d.dst_port = 8308;
    d.payload = b;
    EXPECT_TRUE(w->write(d));
  }
  auto r = PcapReader::open(path);
  ASSERT_TRUE(r.has_value()) << r.error();
  auto d1 = r->next();
  ASSERT_TRUE(d1);
  EXPECT_EQ(d1->host_time.ns, 1'700'000'000'123'456'789);
  EXPECT_EQ(d1->src_ip, testing::ipv4(192, 168, 1, 201));
  EXPECT_EQ(d1->dst_port, 2368);
  EXPECT_EQ(testing::Bytes(d1->payload.begin(), d1->payload.end()), a);
  auto d2 = r->next();
  ASSERT_TRUE(d2);
  EXPECT_EQ(d2->host_time.ns, 1'700'000'001'000'000'001);
  EXPECT_EQ(d2->dst_port, 8308);
  EXPECT_EQ(testing::Bytes(d2->payload.begin(), d2->payload.end()), b);
  EXPECT_FALSE(r->next());
  EXPECT_EQ(r->stats().drops, (std::array<std::uint64_t, kFrameDropCount>{}));
}

TEST(PcapWriter, CannotCreateSaysWhere) {
  auto w = PcapWriter::create("/nonexistent/dir/rec.pcap");
  ASSERT_FALSE(w.has_value());
  EXPECT_NE(w.error().find("/nonexistent/dir/rec.pcap"), std::string::npos) << w.error();
}

}  // namespace
}  // namespace fieldguard::io
