#pragma once
// One JSON line per frame (a rotation, or a fused frame) for `replay --obstacles-out`. Numbers are printed with fixed
// decimals so the same input gives byte-identical output. Written by hand, not with nlohmann/json like the other JSON
// lines: nlohmann has no fixed-decimals output, and it took 1.4-1.5 times as long (benchmarks/json_writers_bench.cpp).

#include <string>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/core/mounting.hpp"
#include "fieldguard/engine/fusion.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

// {"frame":i,"stamp":s,"partial":b,"points_in":n,"obstacles":[{"min":[x,y,z],"max":[x,y,z],"points":n,
//  "obb":{"center":[x,y],"length":l,"width":w,"yaw":rad},"distance":m,"bearing":deg,"height":m,"class":"small"}]}
// A fused frame (fusion.hpp) adds, after "points_in":
//  "fusion":{"levelling":"full"|"attitude_only"|"none","rotations":n,"scan_points":n,"missing":["gnss",...],
//            "timed_out":b,"dropped_points":n,"pose":{"easting":m,"northing":m,"up":m,"zone":z,"roll":deg,
//            "pitch":deg,"yaw":deg}}   (pose when levelling is full; roll/pitch/yaw alone when attitude_only)
// and to each obstacle the 2D LiDAR saw "seen_by":"2d" (its scan alone) or "3d+2d", and when the pose is
// known "plane":[easting,northing,up]: the centre of its box's
// footprint at the box's bottom, in plane coordinates (lidar: the 3D LiDAR's mounting, the detection
// frame's origin in the level frame).
// "full", "attitude_only" or "none", as the "fusion" object's "levelling" says it.
[[nodiscard]] const char* levelling_name(geo::Levelling l);

[[nodiscard]] std::string obstacles_json_line(const LidarFrame& frame, const perception::FrameResult& result,
                                              const FusionInfo* fusion = nullptr, const Mounting* lidar = nullptr);

}  // namespace fieldguard::app
