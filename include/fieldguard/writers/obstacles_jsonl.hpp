#pragma once
// One JSON line per frame (a rotation, or a fused frame) for `replay --obstacles-out`. Numbers are printed with fixed
// decimals so the same input gives byte-identical output. Written by hand, not with nlohmann/json like the other JSON
// lines: nlohmann has no fixed-decimals output, and it took 1.4-1.5 times as long (benchmarks/json_writers_bench.cpp).

#include <string>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/mounting.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/output/safety_monitor.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

// {"version":2,"frame":i,"stamp":s,"partial":b,"points_in":n,
//  "decision":{"stop":b,"reason":"obstacle in zone","reasons":["obstacle in zone",...],"headline":"STOP obstacle
//  5.4 m ahead"},
//  "obstacles":[{"min":[x,y,z],"max":[x,y,z],"points":n,"obb":{"center":[x,y],"length":l,"width":w,"yaw_deg":deg},
//  "distance":m,"bearing":deg,"height":m,"class":"small"}]}
// Lengths in metres, angles in degrees (version 1 gave the box's yaw in radians as "yaw"). Its JSON Schema:
// docs/obstacles.schema.json. "decision" when the safety monitor decided the frame (replay always does), with
// "reason" "none" when it is go and "reasons" every active reason (safety_monitor.hpp).
// A fused frame (fusion.hpp) adds, after "decision" (or "points_in"):
//  "fusion":{"levelling":"full"|"attitude_only"|"none","rotations":n,"scan_points":n,"missing":["gnss",...],
//            "timed_out":b,"dropped_points":n,"pose":{"easting":m,"northing":m,"up":m,"zone":z,"roll":deg,
//            "pitch":deg,"yaw":deg}}   (pose when levelling is full; roll/pitch/yaw alone when attitude_only)
// and to each obstacle the 2D LiDAR saw "seen_by":"2d" (its scan alone) or "3d+2d", and when the pose is
// known "plane":[easting,northing,up]: the centre of its box's
// footprint at the box's bottom, in plane coordinates (lidar: the 3D LiDAR's mounting, the detection
// frame's origin in the level frame).
// "full", "attitude_only" or "none", as the "fusion" object's "levelling" says it.
[[nodiscard]] const char* levelling_name(geo::Levelling l);

// The lines' format version ("version"), raised on any change a reader must know of.
inline constexpr int kObstaclesJsonVersion = 2;

// `decision` and `clear_frames` (safety.clear_frames, for the headline): the frame's decision, when there is one.
[[nodiscard]] std::string obstacles_json_line(const LidarFrame& frame, const perception::FrameResult& result,
                                              const FusionInfo* fusion = nullptr, const Mounting* lidar = nullptr,
                                              const output::safety::Decision* decision = nullptr, int clear_frames = 3);

}  // namespace fieldguard::app
