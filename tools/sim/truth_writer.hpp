#pragma once
// Ground truth as JSON lines, one per rotation:
//   {"frame": k, "stamp": <pcap time of the rotation's first data packet, s>, "period_s": p,
//    "sensor": "hdl32e|vlp16|rs32", "roll_deg": r, "pitch_deg": q, "sensor_world": [x, y, z], "returns": n,
//    "objects": [{"id": "...", "class": "pedestrian|implement|haystack|house|tree|crown",
//                 "min": [x,y,z], "max": [x,y,z], "hits": n, "raised_hits": r, "distance_m": d}, ...],
//    "terrain": [{"id": "...", "class": "clod|ridge|crop|body", "min": [...], "max": [...], "hits": n,
//                 "raised_hits": r, "distance_m": d}, ...]}
// raised_hits: those of the hits that stood kRaisedM (0.5 m) or more above the field surface under them
// (the true surface point, before range noise): what the object showed of itself above terrain height.
// Boxes in the sensor frame (x forward, y left, z up, m): the axis-aligned bounds of the object's world
// box rotated into the sensor's attitude at the moment the beam swept the object's centre (for an object
// across azimuth 0, straight ahead, the union of its boxes at the rotation's first and last packet: the
// rotation starts and ends there, so both are in it). hits count firings: a dual-return firing whose two echoes
// came from the same target is one hit on it. distance_m is
// the horizontal distance from the sensor origin to the nearest point of that box. "objects" lists every
// real object within 120 m (hits may be 0: hidden or out of the beams); "terrain" only features that
// returned points in the rotation. Keys beyond the (id, period_s, sensor_world, returns) are extras
// (fieldguard-score reads the ones it knows and passes over the rest).
// Written by hand, not with nlohmann/json: nlohmann has neither fixed decimals nor ", " separators on one line,
// so the captures' truth would change, and it took 1.9 times as long (benchmarks/json_writers_bench.cpp).

#include <string>

#include "sim/simulator.hpp"

namespace fieldguard::sim {

[[nodiscard]] std::string truth_json_line(const FrameTruth& truth);  // without the newline

}  // namespace fieldguard::sim
