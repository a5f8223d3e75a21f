#pragma once
// Where a sensor sits on the tractor: position of its origin and its attitude in the vehicle frame
// (x forward, y left, z up, origin on the ground below the rear axle centre). R = Rz(yaw) Ry(pitch) Rx(roll).

namespace fieldguard {

struct Mounting {
  double x_m = 0.0;
  double y_m = 0.0;
  double z_m = 0.0;
  double roll_deg = 0.0;
  double pitch_deg = 0.0;
  double yaw_deg = 0.0;
};

}  // namespace fieldguard
