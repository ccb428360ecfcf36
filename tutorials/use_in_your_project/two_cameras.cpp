// Track a thrown ball in 3-D from two calibrated, unsynchronised cameras with viewline's
// multi-view tracker ([L]: each image point is two linear "viewline" plane constraints).
#include <cstdio>
#include <viewline/core/camera.h>
#include <viewline/core/frames.h>
#include <viewline/core/random.h>
#include <viewline/core/version.h>
#include <viewline/tracking/tracker.h>

using namespace viewline;

// A 640x480 pinhole camera at `eye` looking at the middle of the throw (world: z up, metres).
core::Camera makeCamera(const char* name, const Eigen::Vector3d& eye) {
  core::Camera c;
  c.name = name;
  c.intrinsics.initPersProjWithoutDistortion(600.0, 600.0, 319.5, 239.5);
  c.c_M_w = core::lookAt(eye, Eigen::Vector3d(1.0, 0.0, 1.5), Eigen::Vector3d::UnitZ());
  return c;
}

int main() {
  const std::vector<core::Camera> cameras{makeCamera("left", {1.0, -4.0, 1.5}), makeCamera("right", {5.0, 0.0, 1.5})};
  tracking::ViewlineTracker tracker(cameras, tracking::TrackerConfig{});  // [L]'s prior and ballistic model
  core::Rng rng = core::makeRng(1);                                      // seeded: the run is reproducible
  const Eigen::Vector3d p0(0.0, 0.0, 1.0), v0(3.0, 0.0, 4.0), g(0.0, 0.0, -9.81);
  const double sigma_px = 0.5;
  Eigen::Vector3d truth = p0;
  std::uint64_t id = 0;
  for (int k = 0; k < 70; ++k) {
    // Camera 0 at 50 Hz, camera 1 at 50 Hz shifted by 7 ms: unsynchronised, each image time-stamped.
    const std::size_t cam = k % 2;
    const double t = 0.02 * (k / 2) + (cam == 1 ? 0.007 : 0.0);
    truth = p0 + v0 * t + 0.5 * g * t * t;
    auto uv = cameras[cam].project(truth);
    if (!uv || !cameras[cam].inImage(*uv)) continue;
    *uv += Eigen::Vector2d(core::gaussian(rng, sigma_px), core::gaussian(rng, sigma_px));
    const auto refused = tracker.submit({++id, cam, t, *uv, sigma_px});
    if (refused != tracking::Refusal::None) std::printf("refused: %s\n", tracking::toString(refused));
  }
  const Eigen::Vector3d p = tracker.state().x().head<3>();
  std::printf("viewline %s: %llu images, position error %.1f mm at t = %.3f s\n", core::kVersion,
              static_cast<unsigned long long>(id), 1000.0 * (p - truth).norm(), tracker.state().t());
  return (p - truth).norm() < 0.02 ? 0 : 1;  // a tracker that lost the ball fails the check
}
