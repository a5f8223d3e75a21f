#include "fieldguard/io/pcap_reader.hpp"

#include <pcap/pcap.h>

#include <cerrno>
#include <cstdio>
#include <string_view>
#include <system_error>
#include <utility>

namespace fieldguard::io {
namespace {

constexpr std::uint32_t kPcapngSectionHeader = 0x0A0D0D0A;

[[nodiscard]] std::string errno_text(int err) { return std::error_code(err, std::generic_category()).message(); }

[[nodiscard]] std::string hex32(std::uint32_t v) {
  std::array<char, 11> buf{};
  std::snprintf(buf.data(), buf.size(), "0x%08x", v);
  return buf.data();
}

// libpcap reports the data link type (DLT_); extract_udp takes the file's LINKTYPE_. They differ only
// for raw IP, whose DLT_ value is OS-specific (12 on Linux) while files say LINKTYPE_RAW (101).
[[nodiscard]] int linktype_of_dlt(int dlt) { return dlt == DLT_RAW ? kLinkRaw : dlt; }

// Record time in ns since the epoch. The reader is opened with nanosecond precision, so tv_usec holds
// nanoseconds. pcapng timestamps are 64-bit and libpcap scales them without range checks: saturate
// instead of overflowing on a damaged file.
[[nodiscard]] Stamp stamp_of(const timeval& tv) {
  std::int64_t ns = 0;
  const auto sec = static_cast<std::int64_t>(tv.tv_sec);
  const auto frac = static_cast<std::int64_t>(tv.tv_usec);
  if (__builtin_mul_overflow(sec, std::int64_t{1'000'000'000}, &ns) || __builtin_add_overflow(ns, frac, &ns)) {
    ns = sec < 0 ? INT64_MIN : INT64_MAX;
  }
  return Stamp{ns};
}

// The first bytes of a file, read before libpcap sees it.
struct Peek {
  std::uint32_t magic = 0;
  std::size_t size = 0;  // bytes peeked, up to kPeekSize
};
// Magic, and for pcapng the block length and byte-order magic that libpcap checks before it says
// "unknown file format".
constexpr std::size_t kPeekSize = 12;

// What libpcap's open error means for this file, as one line naming it.
[[nodiscard]] std::string open_error(const std::string& name, std::string_view pcap_message,
                                     const std::optional<Peek>& peek) {
  if (pcap_message.starts_with("unknown file format") && peek) {
    if (peek->magic == kPcapngSectionHeader) {
      if (peek->size < kPeekSize) {
        return name + " is cut short inside its file header (" + std::to_string(peek->size) +
               " bytes of a pcapng section header)";
      }
      return name + " is not a readable pcapng file: bad byte-order magic in its section header";
    }
    return name + " is not a pcap or pcapng file (magic " + hex32(peek->magic) + ")";
  }
  if (pcap_message.find("truncated") != std::string_view::npos) {
    return name + " is cut short inside its file header (" + std::string(pcap_message) + ")";
  }
  return name + ": " + std::string(pcap_message);
}

}  // namespace

struct PcapReader::Impl {
  pcap_t* pcap = nullptr;
  int link_type = 0;  // LINKTYPE_ value, see linktype_of_dlt
  bool done = false;  // end of file or an error: next() returns nullopt from now on

  Impl(pcap_t* p, int lt) : pcap(p), link_type(lt) {}
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;
  ~Impl() { pcap_close(pcap); }
};

PcapReader::PcapReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
PcapReader::PcapReader(PcapReader&&) noexcept = default;
PcapReader& PcapReader::operator=(PcapReader&&) noexcept = default;
PcapReader::~PcapReader() = default;

Expected<PcapReader, std::string> PcapReader::open(const std::string& path) {
  std::FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return Unexpected{"cannot open " + path + ": " + errno_text(errno)};
  return open(file, path);
}

Expected<PcapReader, std::string> PcapReader::open(std::FILE* file, const std::string& name) {
  if (file == nullptr) return Unexpected{"cannot open " + name + ": no file given"};

  // Peek at the magic where the stream can seek back (files, fmemopen; not pipes): libpcap's messages
  // for an empty or foreign file name neither the file nor what it found.
  std::optional<Peek> peek;
  const long start = std::ftell(file);
  if (start >= 0) {
    std::array<std::uint8_t, kPeekSize> head{};
    errno = 0;
    const std::size_t got = std::fread(head.data(), 1, head.size(), file);
    const int read_errno = errno;
    if (std::ferror(file) != 0) {
      std::fclose(file);
      return Unexpected{"cannot read " + name + ": " + errno_text(read_errno)};
    }
    if (std::fseek(file, start, SEEK_SET) != 0) {
      const int seek_errno = errno;
      std::fclose(file);
      return Unexpected{"cannot read " + name + ": " + errno_text(seek_errno)};
    }
    if (got == 0) {
      std::fclose(file);
      return Unexpected{name + " is empty: not a pcap or pcapng file"};
    }
    if (got < 4) {
      std::fclose(file);
      return Unexpected{name + " is too short to be a pcap or pcapng file (" + std::to_string(got) + " bytes)"};
    }
    peek = Peek{load_be32(head, 0), got};
  }

  std::array<char, PCAP_ERRBUF_SIZE> errbuf{};
  pcap_t* pcap = pcap_fopen_offline_with_tstamp_precision(file, PCAP_TSTAMP_PRECISION_NANO, errbuf.data());
  if (pcap == nullptr) {
    std::fclose(file);  // libpcap takes the FILE only on success
    return Unexpected{open_error(name, errbuf.data(), peek)};
  }
  // One link type per file: libpcap's pcapng reader takes it from the first interface and refuses
  // (a read error, "an interface has a type N different from the type of the first interface") an
  // interface of another type, and pcap_next_ex() does not say which interface a packet came from.
  const int link_type = linktype_of_dlt(pcap_datalink(pcap));
  return PcapReader(std::make_unique<Impl>(pcap, link_type));
}

int PcapReader::link_type() const { return impl_ ? impl_->link_type : 0; }

std::optional<UdpDatagram> PcapReader::next() {
  if (!impl_ || impl_->done) return std::nullopt;
  for (;;) {
    pcap_pkthdr* header = nullptr;
    const u_char* data = nullptr;
    const int rc = pcap_next_ex(impl_->pcap, &header, &data);
    if (rc == 1) {
      ++stats_.records;
      const ByteSpan frame(data, header->caplen);
      auto result = extract_udp(impl_->link_type, frame, header->len, stamp_of(header->ts));
      if (!result) {
        ++stats_.drops[static_cast<std::size_t>(result.error())];
        continue;
      }
      ++stats_.datagrams;
      if (result->ip_length_repaired) ++stats_.ip_length_repaired;
      return std::move(result).value();
    }
    impl_->done = true;
    if (rc == PCAP_ERROR_BREAK) return std::nullopt;  // end of file
    // libpcap says "truncated dump file; ..." (pcap) or "truncated pcapng dump file; ..." when the file
    // ends inside a record: a capture that was cut off, not a damaged one.
    const std::string message = pcap_geterr(impl_->pcap);
    if (message.find("truncated") != std::string::npos) {
      stats_.truncated = true;
    } else {
      stats_.read_error = message.empty() ? "pcap_next_ex returned " + std::to_string(rc) : message;
    }
    return std::nullopt;
  }
}

}  // namespace fieldguard::io
