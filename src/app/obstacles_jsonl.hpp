#pragma once
// One JSON line per rotation for `replay --obstacles-out`. Numbers are printed with fixed decimals so the
// same input gives byte-identical output.

#include <string>

#include "fieldguard/core/lidar_point.hpp"
#include "fieldguard/perception/obstacle.hpp"

namespace fieldguard::app {

// {"frame":i,"stamp":s,"partial":b,"points_in":n,"obstacles":[{"min":[x,y,z],"max":[x,y,z],"points":n,
//  "obb":{"center":[x,y],"length":l,"width":w,"yaw":rad},"distance":m,"bearing":deg,"height":m,"class":"small"}]}
[[nodiscard]] std::string obstacles_json_line(const LidarFrame& frame, const perception::FrameResult& result);

}  // namespace fieldguard::app
