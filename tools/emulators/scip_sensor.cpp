#include "scip_sensor.hpp"

#include <algorithm>
#include <cstdlib>

#include "fieldguard/drivers/scip.hpp"

namespace fieldguard::tools {

namespace {

// A status or echo line with its check character ("00" -> "00P").
std::string with_check(const std::string& s) { return s + scip::check_code(s) + "\n"; }

// "LABEL:value;S" as the VV/PP/II replies have it: the check covers LABEL:value.
std::string info_line(const std::string& kv) { return kv + ";" + scip::check_code(kv) + "\n"; }

}  // namespace

std::string ScipSensor::reply(std::string_view line_view) {
  const std::string line(line_view);
  const std::string cmd = line.substr(0, std::min<std::size_t>(2, line.size()));
  std::string reply = line + "\n";
  if (line.rfind("SCIP2.0", 0) == 0) {
    reply += with_check("00") + "\n";
  } else if (cmd == "VV") {
    reply += with_check("00") + info_line("VEND:Hokuyo Automatic Co.,Ltd.") +
             info_line("PROD:SOKUIKI Sensor UTM-30LX-EW") + info_line("FIRM:" + id_.firmware) +
             info_line("PROT:SCIP 2.0") + info_line("SERI:" + id_.serial) + "\n";
  } else if (cmd == "PP") {
    reply += with_check("00") + info_line("MODL:UTM-30LX-EW") + info_line("DMIN:23") + info_line("DMAX:60000") +
             info_line("ARES:1440") + info_line("AMIN:0") + info_line("AMAX:1080") + info_line("AFRT:540") +
             info_line("SCAN:2400") + "\n";
  } else if (cmd == "II") {
    reply += with_check("00") + info_line("MODL:UTM-30LX-EW") + info_line(laser_ ? "LASR:ON" : "LASR:OFF") +
             info_line("SCSP:2400") + info_line("MESM:Measuring by Sensitive Mode") +
             info_line("SBPS:Ethernet 100 [Mbps]") + info_line("TIME:000000") + info_line("STAT:Stable 000 no error.") +
             "\n";
  } else if (cmd == "BM") {
    if (id_.refuse_laser) {
      reply += with_check("01") + "\n";
    } else {
      reply += with_check(laser_ ? "02" : "00") + "\n";
      laser_ = true;
    }
  } else if ((cmd == "MD" || cmd == "ME") && line.size() >= 15) {
    const int first = std::atoi(line.substr(2, 4).c_str());
    const int last = std::atoi(line.substr(6, 4).c_str());
    if (first > last || last > 1080) {
      reply += with_check("04") + "\n";
    } else {
      reply += with_check("00") + "\n";
      first_ = first;
      last_ = last;
      laser_ = true;
      streaming_ = true;
      intensity_ = cmd == "ME";
      echo_ = line;
    }
  } else if (cmd == "QT" || cmd == "RS") {
    streaming_ = false;
    laser_ = false;
    reply += with_check("00") + "\n";
  } else {
    reply += with_check("0E") + "\n";
  }
  return reply;
}

std::string ScipSensor::scan(std::span<const std::uint32_t> ranges, std::span<const std::uint32_t> intensities,
                             std::uint32_t time_ms) const {
  std::string out = echo_ + "\n" + with_check("99");
  std::string ts;
  scip::encode_chars(time_ms & 0xFFFFFFU, 4, ts);
  out += with_check(ts);
  std::string data;
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    scip::encode_chars(ranges[i], 3, data);
    if (intensity_) scip::encode_chars(i < intensities.size() ? intensities[i] : 0U, 3, data);
  }
  for (std::size_t i = 0; i < data.size(); i += scip::kDataCharsPerLine)
    out += with_check(data.substr(i, scip::kDataCharsPerLine));
  return out + "\n";
}

}  // namespace fieldguard::tools
