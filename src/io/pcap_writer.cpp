#include "fieldguard/io/pcap_writer.hpp"

#include <pcap/pcap.h>

#include <vector>

namespace fieldguard::io {

struct PcapWriter::Impl {
  pcap_t* dead = nullptr;
  pcap_dumper_t* dumper = nullptr;
  std::vector<std::uint8_t> frame;
  std::uint16_t ip_id = 0;
  ~Impl() {
    if (dumper != nullptr) pcap_dump_close(dumper);
    if (dead != nullptr) pcap_close(dead);
  }
};

namespace {

void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  b[at] = static_cast<std::uint8_t>(v >> 8);
  b[at + 1] = static_cast<std::uint8_t>(v);
}
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  put16(b, at, v >> 16);
  put16(b, at + 2, v & 0xFFFFU);
}

}  // namespace

Expected<PcapWriter, std::string> PcapWriter::create(const std::string& path) {
  auto impl = std::make_unique<Impl>();
  impl->dead = pcap_open_dead_with_tstamp_precision(DLT_EN10MB, 65535, PCAP_TSTAMP_PRECISION_NANO);
  if (impl->dead == nullptr) return Unexpected{std::string("libpcap cannot make a capture handle")};
  impl->dumper = pcap_dump_open(impl->dead, path.c_str());
  if (impl->dumper == nullptr) return Unexpected{"cannot create " + path + ": " + pcap_geterr(impl->dead)};
  return PcapWriter(std::move(impl));
}

PcapWriter::PcapWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PcapWriter::PcapWriter(PcapWriter&&) noexcept = default;
PcapWriter& PcapWriter::operator=(PcapWriter&&) noexcept = default;
PcapWriter::~PcapWriter() = default;

bool PcapWriter::write(const UdpDatagram& d) {
  constexpr std::size_t kEth = 14;
  constexpr std::size_t kIp = 20;
  constexpr std::size_t kUdp = 8;
  if (d.payload.size() > 65535 - kIp - kUdp) return false;
  auto& f = impl_->frame;
  f.assign(kEth + kIp + kUdp + d.payload.size(), 0);
  for (std::size_t i = 0; i < 6; ++i) f[i] = 0xFF;  // broadcast, as Velodyne sensors send by default
  put16(f, 12, 0x0800);
  const std::size_t ip = kEth;
  f[ip] = 0x45;
  put16(f, ip + 2, static_cast<std::uint32_t>(kIp + kUdp + d.payload.size()));
  put16(f, ip + 4, impl_->ip_id++);
  put16(f, ip + 6, 0x4000);  // don't fragment
  f[ip + 8] = 64;
  f[ip + 9] = 17;
  put32(f, ip + 12, d.src_ip);
  put32(f, ip + 16, d.dst_ip);
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < kIp; i += 2) sum += static_cast<std::uint32_t>((f[ip + i] << 8) | f[ip + i + 1]);
  while ((sum >> 16) != 0) sum = (sum & 0xFFFFU) + (sum >> 16);
  put16(f, ip + 10, ~sum & 0xFFFFU);
  const std::size_t udp = ip + kIp;
  put16(f, udp, d.src_port);
  put16(f, udp + 2, d.dst_port);
  put16(f, udp + 4, static_cast<std::uint32_t>(kUdp + d.payload.size()));  // checksum 0: none (IPv4)
  std::copy(d.payload.begin(), d.payload.end(), f.begin() + static_cast<std::ptrdiff_t>(udp + kUdp));

  pcap_pkthdr h{};
  h.ts.tv_sec = static_cast<time_t>(d.host_time.ns / 1'000'000'000);
  h.ts.tv_usec = static_cast<suseconds_t>(d.host_time.ns % 1'000'000'000);  // nanoseconds with NANO precision
  h.caplen = static_cast<bpf_u_int32>(f.size());
  h.len = h.caplen;
  pcap_dump(reinterpret_cast<u_char*>(impl_->dumper), &h, f.data());
  return true;
}

bool PcapWriter::flush() { return pcap_dump_flush(impl_->dumper) == 0; }

}  // namespace fieldguard::io
