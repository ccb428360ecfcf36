#pragma once
// Test fixtures: tiny ray-casting renderer (anti-aliased by supersampling)
// for the vision unit tests and benchmarks. Exact geometry through
// core::Camera (with its distortion), so ground truth is known precisely.
// Not the product's renderer (module sim): only what the tests need.

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"

namespace viewline::vision::test {

/// Smooth random texture (grey-brown), seeded.
cv::Mat texturedBackground(int width, int height, std::uint64_t seed, double mean = 110.0, double amp = 40.0);

/// Shaded sphere of radius r (world centre c_w): colour `bgr` scaled by 0.55..1.0 with a
/// Lambertian light from the camera's upper left. `ss` samples per pixel side.
void renderSphere(cv::Mat& img, const core::Camera& cam, const Eigen::Vector3d& c_w, double r,
                  const cv::Vec3b& bgr, int ss = 4, bool shaded = true);

/// Square table of side L (red) with a black border of width `border` around it, in the plane
/// z = 0 of the table frame w_M_t (origin at the centre).
void renderTable(cv::Mat& img, const core::Camera& cam, const Eigen::Isometry3d& w_M_t, double side,
                 double border, const cv::Vec3b& red = {30, 30, 200}, int ss = 3);

/// An AprilTag 36h11 of black-square side `size` (id) lying in the z = 0 plane of w_M_tag,
/// tag frame as vpDetectorAprilTag's (default): x right, y up in the tag image, z out of the
/// tag towards the viewer; cell (col, row) covers x in [(col - 5) s, (col - 4) s],
/// y in [(4 - row) s, (5 - row) s], s = size / 8; white quiet zone of one cell.
void renderTag36h11(cv::Mat& img, const core::Camera& cam, const Eigen::Isometry3d& w_M_tag, int id,
                    double size, int ss = 3);

/// Dark disc (value `dark`) of radius R px at (u, v) on a bright screen (`bright`), grey image.
cv::Mat screenWithDisc(int width, int height, double u, double v, double R, int bright = 220,
                       int dark = 30, int ss = 4);

/// Adds N(0, sigma²) noise to every channel (seeded).
void addNoise(cv::Mat& img, double sigma, core::Rng& rng);

}  // namespace viewline::vision::test
