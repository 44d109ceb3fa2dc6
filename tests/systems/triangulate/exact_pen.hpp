#pragma once
// An exactly observed pen for the tracking tests: two cameras looking at a pen on a smooth path, blobs
// unrounded and noise-free, so what a test measures is the method's own error.
#include <Eigen/Geometry>
#include <cmath>
#include <initializer_list>

#include "systems/tracking/track.hpp"

namespace fire::tracking::test {

inline Camera look_at(const Vec3& centre, const Vec3& target, double k1) {
  const Vec3 z = (target - centre).normalized();
  const Vec3 y = (Vec3::UnitY() - Vec3::UnitY().dot(z) * z).normalized();
  Eigen::Matrix3d R;
  R.row(0) = y.cross(z);
  R.row(1) = y;
  R.row(2) = z;
  Intrinsics K = wiimote_nominal_intrinsics();
  K.k1 = k1;
  return Camera{K, R, -R * centre};
}

struct Rig {
  Camera c0 = look_at(Vec3(-0.25, 0, 0), Vec3(0, 0, 0.8), 0.03);
  Camera c1 = look_at(Vec3(0.25, 0, 0), Vec3(0, 0, 0.8), 0.02);
};

// A pen tip moving on a smooth closed path in front of the rig (t in seconds).
inline Vec3 pen_path(double t) {
  return Vec3(0.08 * std::sin(2.1 * t), 0.06 * std::sin(3.3 * t + 0.4), 0.8 + 0.05 * std::cos(1.7 * t));
}

inline void push_frame(CameraFrames& f, double t_us, std::initializer_list<Vec2> blobs) {
  f.t_us.push_back(std::llround(t_us));
  f.line.push_back(0);
  f.t_frame_us.push_back(t_us);
  std::array<Vec2, kIrSlots> b;
  b.fill(Vec2::Zero());
  uint8_t n = 0;
  for (const Vec2& p : blobs) b[n++] = p;
  f.blob_count.push_back(n);
  f.blobs.push_back(b);
}

// Exact (unrounded, noise-free) blobs: camera 0 exposes at 10 ms steps, camera 1 at 10.001 ms
// steps from a 3.7 ms phase; camera 1 stamps every instant `offset_us` late. From `stray_from_s`
// on, camera 1 also sees a stray blob exactly on the pen's epipolar line: the image of a point
// 25 % farther along camera 0's ray through the pen.
inline DeviceStreams exact_streams(const Rig& rig, double seconds, double offset_us, double stray_from_s) {
  DeviceStreams s;
  for (double t = 0.0; t < seconds; t += 0.010) push_frame(s.cameras[0], t * 1e6, {rig.c0.project(pen_path(t))});
  for (double t = 0.0037; t < seconds; t += 0.010001) {
    const Vec2 pen = rig.c1.project(pen_path(t));
    const Vec3 ghost = rig.c0.centre() + 1.25 * (pen_path(t) - rig.c0.centre());
    if (t >= stray_from_s)
      push_frame(s.cameras[1], t * 1e6 + offset_us, {rig.c1.project(ghost), pen});
    else
      push_frame(s.cameras[1], t * 1e6 + offset_us, {pen});
  }
  return s;
}

}  // namespace fire::tracking::test
