#pragma once
// Ray-cast renderer for the simulated cameras.
//
// Image contract (what the detectors of module vision receive): cv::Mat CV_8UC3 (BGR), of the
// camera's width x height, rendered through the camera's ViSP intrinsics *with* distortion: a
// world point p_w appears at core::Camera::project(p_w), i.e. at
//     u = u0 + px · x (1 + kud (x² + y²)),  v = v0 + py · y (1 + kud (x² + y²)),  (x, y) = (X/Z, Y/Z)
// (vpMeterPixelConversion of ViSP 3.5 applies kud in this direction; vpPixelMeterConversion
// applies kdu in the other, an approximate inverse). Pixel centres are at integer (u, v); pixel (i, j) covers
// [i-½, i+½] x [j-½, j+½]. Every pixel casts the exact ray of that model: the map pixel ->
// normalised coordinates inverts the kud model exactly (Newton on the radial polynomial), once
// per camera, at pixel centres and corners.
//
// Anti-aliasing: a pixel is sampled at its four corners; when they hit different objects or
// differ in colour by more than `edge_threshold`, the pixel is the mean of n x n sub-samples
// (rays interpolated bilinearly from the corner rays), otherwise its centre sample. Objects
// flagged `thin` are supersampled on their whole footprint. The coverage of a pixel by a sphere
// edge is therefore exact to 1/n² of a pixel.
//
// Speed: objects of World::staticScene() are rendered once per camera (pose, intrinsics and
// size) and cached with their depth; each frame copies that layer and ray-casts only the
// bounding boxes of the moving objects against it. Motion blur: the moving objects are
// rendered at `blur_samples` instants spread evenly over the exposure and averaged.

#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <vector>

#include "viewline/core/camera.h"
#include "viewline/sim/scene.h"

namespace viewline::sim {

/// A world the cameras look at: a static part (cached) and moving objects queried by time.
class World {
public:
  virtual ~World() = default;
  /// Objects that never move. The renderer caches their image per camera; bump staticVersion()
  /// when they change.
  virtual const Scene& staticScene() const = 0;
  /// Appends the moving objects at time t (s) to `out`.
  virtual void dynamicObjects(double t, std::vector<Primitive>& out) const = 0;
  /// The single directional light of the world (default: Lighting{}).
  virtual Lighting lighting() const { return Lighting{}; }
  /// Version of the static scene; a change makes the renderer rebuild its cached layers.
  virtual std::uint64_t staticVersion() const { return 0; }
};

/// A world made of a fixed Scene plus a callback for the moving objects (handy in tests and apps).
class SceneWorld : public World {
public:
  /// Appends the moving objects at time t (s) to the output list.
  using Dynamic = std::function<void(double t, std::vector<Primitive>& out)>;
  /// A world of `scene` (static), `dynamic` (moving objects; may be empty) and one light.
  explicit SceneWorld(Scene scene, Dynamic dynamic = nullptr, Lighting lighting = {});
  const Scene& staticScene() const override { return scene_; }
  void dynamicObjects(double t, std::vector<Primitive>& out) const override;
  Lighting lighting() const override { return lighting_; }
  Scene& scene() { ++version_; return scene_; }  ///< mutable access (invalidates the cache)
  std::uint64_t staticVersion() const override { return version_; }

private:
  Scene scene_;
  Dynamic dynamic_;
  Lighting lighting_;
  std::uint64_t version_ = 0;
};

/// Quality and cache settings of the renderer.
struct RenderSettings {
  int supersampling = 4;          ///< n: n x n sub-samples on edge pixels (1 = no anti-aliasing)
  double edge_threshold = 0.03;   ///< corner colour difference (reflectance units) that triggers it
  int max_cached_cameras = 8;     ///< static layers kept (least recently used dropped)
};

/// One exposure of one camera.
struct ExposureSpec {
  double time = 0.0;        ///< capture time = middle of the exposure, s
  double duration = 0.0;    ///< exposure time, s (0: instantaneous, no motion blur)
  int blur_samples = 1;     ///< instants averaged over the exposure (>= 1)
};

/// Ray-cast renderer of simulated cameras: exact ViSP kud projection, anti-aliased edges, cached static
/// layers, motion blur.
class Renderer {
public:
  /// Renderer with these settings.
  explicit Renderer(const RenderSettings& settings = {});
  ~Renderer();
  /// Takes over another renderer's caches.
  Renderer(Renderer&&) noexcept;
  /// Takes over another renderer's caches.
  Renderer& operator=(Renderer&&) noexcept;

  /// Renders `world` seen by `camera` over the exposure. `extra` are additional moving objects
  /// (e.g. an occluder) assumed fixed during the exposure. When `truth` is non-null it receives
  /// one entry per named primitive (static and moving, the latter at exposure.time).
  /// Throws core::InvalidInput for a zero-size camera, NaN time, negative exposure, blur_samples < 1.
  cv::Mat render(const World& world, const core::Camera& camera, const ExposureSpec& exposure,
                 std::vector<ObjectTruth>* truth = nullptr, const std::vector<Primitive>& extra = {});

  /// Convenience: renders a scene with no moving objects, without caching.
  cv::Mat renderScene(const Scene& scene, const core::Camera& camera, const Lighting& lighting = {});

  /// The settings in use.
  const RenderSettings& settings() const { return settings_; }

private:
  struct Impl;
  RenderSettings settings_;
  std::unique_ptr<Impl> impl_;
};

/// Ground truth of one primitive seen by a camera (projections only; visibility is left at -1).
ObjectTruth describe(const Primitive& primitive, const core::Camera& camera);

/// Exact inverse of the camera's distortion model: normalised coordinates whose projection is
/// pixel uv (NaN when uv lies outside the range the model can reach).
Eigen::Vector2d undistortExact(const core::Camera& camera, const Eigen::Vector2d& uv);

}  // namespace viewline::sim
