#pragma once
// Renders images of a calibration board seen by a calibrated camera: a perspective warp of a
// high-resolution board texture, ViSP radial distortion (kud) when the camera has it, blur and
// Gaussian sensor noise. Used for synthetic calibration data (tests, tutorials, the default
// simulated rigs): the tools then calibrate from these images, as from real ones.

#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include "viewline/calib/board.h"
#include "viewline/core/camera.h"
#include "viewline/core/random.h"

namespace viewline::calib {

/// Imaging effects of renderBoard(): blur, noise, background and supersampling.
struct RenderOptions {
  double blur_sigma_px = 0.6;    ///< Gaussian blur (optics)
  double noise_sigma = 2.0;      ///< grey levels
  int background = 128;          ///< grey level around the board
  int supersample = 2;           ///< rendered at this factor, then area-averaged
};

/// Board texture (8-bit, white paper with the pattern): texture pixel (u, v) shows the board point
/// (origin.x + u / ppm, origin.y + v / ppm). One spacing (or tag size) of white margin around.
cv::Mat boardTexture(const BoardSpec& board, double pixels_per_metre, cv::Point2d& origin);

/// Grey image of the board at pose c_M_o (board -> camera) through `camera` (its width/height).
cv::Mat renderBoard(const core::Camera& camera, const Eigen::Isometry3d& c_M_o, const BoardSpec& board,
                    core::Rng& rng, const RenderOptions& options = {});

}  // namespace viewline::calib
