#pragma once
// Imaging effects of one simulated camera. Each is off by default, set from the scenario
// config, and deterministic per seed (all draws come from the camera's own core::Rng streams).
//
// Order in a frame (CameraRig): render with motion blur (and the occluder) -> illumination and
// white balance (per-channel gains on the 8-bit values) -> sensor noise -> 8-bit.
// Frame faults (drops, time-stamp jitter) act on the schedule, not on the pixels.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/core/random.h"
#include "viewline/sim/scene.h"

namespace viewline::sim {

/// Additive Gaussian sensor noise, independent per pixel and channel: I' = sat(I + n),
/// n ~ N(0, sigma²) rounded to integers. For speed the values come from a pool of
/// `pool_size` seeded draws (8-bit, clipped at ±127) read at a random offset per frame (so any
/// pixel's noise is a fresh N(0, σ²) draw; two frames share values only at different, shifted
/// pixels). Images larger than the pool, and sigma > 40, use cv::randn per frame instead.
struct SensorNoise {
  double sigma = 0.0;            ///< grey levels (0..255 scale), >= 0
  std::size_t pool_size = 1u << 21;  ///< >= 1024; images up to this many values use the pool
};

/// Motion blur: the moving objects are rendered at `samples` instants evenly spread over the
/// exposure [t - exposure/2, t + exposure/2] (t = capture time stamp) and averaged.
struct MotionBlur {
  double exposure = 0.0;  ///< s, >= 0 (0: no blur)
  int samples = 5;        ///< >= 1
};

/// Illumination and white balance: per-channel gain
///   g_c(t) = gain · (1 + flicker_amplitude · sin(2π flicker_frequency t)) · (1 + drift · t) · wb_c
/// applied to the rendered image (saturating). Light direction changes belong to the World.
struct Illumination {
  double gain = 1.0;                                              ///< global brightness factor, > 0
  Eigen::Vector3d white_balance_bgr = Eigen::Vector3d::Ones();    ///< per-channel gains, > 0
  double flicker_amplitude = 0.0;                                 ///< relative, in [0, 1)
  double flicker_frequency = 0.0;                                 ///< Hz, >= 0
  double drift = 0.0;                                             ///< relative change per second
};

/// Partial occlusion of a named target by an occluder object: a flat rectangle facing the
/// camera at `depth_ratio` of the target's depth, whose straight edge cuts the target's
/// apparent disc so that `fraction` of its area is hidden. The edge normal points along
/// `direction` (rad, image x towards image y) or a uniform random direction per frame.
struct Occlusion {
  std::string target = "ball";  ///< name of the occluded primitive
  double fraction = 0.0;                                          ///< [0, 1]
  bool random_direction = true;  ///< draw the edge direction uniformly per frame (else `direction`)
  double direction = 0.0;                                         ///< rad, used when not random
  double depth_ratio = 0.5;                                       ///< (0, 1)
  Eigen::Vector3d colour_bgr = Eigen::Vector3d(0.35, 0.33, 0.3);  ///< occluder reflectance (BGR, [0, 1])
};

/// Faults of the camera link: frames lost and imprecise time stamps.
struct FrameFaults {
  double drop_probability = 0.0;   ///< each frame lost independently, [0, 1)
  double stamp_jitter = 0.0;       ///< s, std of the reported stamp around the true capture time
  double trigger_jitter = 0.0;     ///< s, std of the true capture instant around its schedule
                                   ///< (clamped to ±0.45 period so frames keep their order)
};

/// Every imaging effect of one simulated camera (all off by default).
struct ImagingEffects {
  SensorNoise noise;  ///< sensor noise
  MotionBlur blur;  ///< motion blur
  Illumination illumination;  ///< illumination and white balance
  Occlusion occlusion;  ///< partial occlusion of a target
  FrameFaults faults;  ///< frame drops and time-stamp jitter
};

/// Throws core::InvalidInput naming the field for out-of-range settings.
void validate(const ImagingEffects& effects);

/// Per-channel gain of the illumination at time t.
Eigen::Vector3d illuminationGain(const Illumination& illumination, double t);
/// Applies the illumination gains in place (no-op when all gains are 1).
void applyIllumination(cv::Mat& bgr8, const Illumination& illumination, double t);

/// Seeded pool of rounded N(0, sigma²) values; apply() adds them at a random offset.
class NoisePool {
public:
  static constexpr double kMaxPoolSigma = 40.0;  ///< above: per-frame cv::randn (no clipping)
  /// Draws pool_size rounded N(0, sigma²) values from rng (none for sigma 0 or above kMaxPoolSigma); throws
  /// core::InvalidInput for bad settings.
  NoisePool(const SensorNoise& noise, core::Rng& rng);
  /// Adds noise to an 8-bit image in place; the offset is drawn from rng.
  void apply(cv::Mat& image8, core::Rng& rng) const;
  /// Per-channel gains (illuminationGain) then noise, in a single pass over the image.
  void applyWithGain(cv::Mat& image8, const Eigen::Vector3d& gain_bgr, core::Rng& rng) const;
  /// Noise standard deviation, grey levels.
  double sigma() const { return sigma_; }

private:
  double sigma_;
  std::vector<std::int8_t> pool_;
};

/// The occluder primitive for a target seen by `camera` (nullopt when the fraction is 0 or the
/// target is not in front of the camera). `direction` in rad as in Occlusion.
std::optional<Primitive> makeOccluder(const ObjectTruth& target, const core::Camera& camera,
                                      const Occlusion& occlusion, double direction);

/// Fraction of a disc of radius 1 lying beyond the chord at signed distance d from its centre:
/// (acos d - d sqrt(1 - d²)) / π, d in [-1, 1].
double discSegmentFraction(double d);

}  // namespace viewline::sim
