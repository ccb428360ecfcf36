#pragma once
// What a simulated camera can see: a list of primitives (spheres, boxes, cylinders, cones,
// textured rectangles, discs), each with a pose w_M_o, a Lambert material and an optional
// name that makes it appear in the ground truth of every frame.
//
// Object frames (o):
//   Sphere     origin at the centre;                size = (radius, -, -)
//   Box        origin at the centre, axis-aligned;  size = full extents (x, y, z)
//   Cylinder   axis along z from z = 0 to z = len;  size = (radius, -, len), both ends capped
//   Cone       base disc at z = 0, apex at z = len; size = (base radius, -, len), base capped
//   Rectangle  in the plane z = 0, centred;         size = (width along x, height along y, -)
//              texture coordinates u = x/width + ½ (image columns), v = y/height + ½ (rows):
//              a camera looking along the object's +z sees the texture unmirrored.
//   Disc       in the plane z = 0, centred;         size = (radius, -, -)
// Planar shapes are two-sided.
//
// Colours are BGR reflectances in [0, 1] (OpenCV channel order). Shading (camera or world
// frame, one directional light):
//   colour = albedo ⊙ texture ⊙ light_bgr · (ambient + (1 - ambient) · max(0, n·l))
// with n the unit surface normal facing the viewer and l the unit direction *towards* the
// light. Unlit materials (screens, projections) show albedo ⊙ texture ⊙ light_bgr.

#include <Eigen/Geometry>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "viewline/core/random.h"

namespace viewline::sim {

/// Geometric primitive kind (see the object frames in the file comment).
enum class Shape { Sphere, Box, Cylinder, Cone, Rectangle, Disc };

/// An image mapped onto a Rectangle: CV_32FC3, BGR reflectances in [0, 1].
struct Texture {
  cv::Mat image;  ///< CV_32FC3 image, BGR reflectances in [0, 1]
  bool nearest = false;  ///< nearest-neighbour lookup (crisp codes: tags); else bilinear
  /// Colour at texture coordinates (u, v) in [0, 1]² (clamped).
  Eigen::Vector3d sample(double u, double v) const;
};

/// Lambert material: reflectance and ambient fraction (or unlit).
struct Material {
  Eigen::Vector3d albedo_bgr = Eigen::Vector3d(0.6, 0.6, 0.6);  ///< reflectance per channel, [0, 1]
  double ambient = 0.35;                                         ///< unshaded fraction, [0, 1]
  bool unlit = false;                                            ///< emits albedo (screens, projections)
};

/// One object of a scene: shape, pose w_M_o, size, material and optional texture or tag identity.
struct Primitive {
  std::string name;                       ///< non-empty: reported in FrameTruth under this name
  Shape shape = Shape::Sphere;  ///< shape kind
  Eigen::Isometry3d w_M_o = Eigen::Isometry3d::Identity();  ///< object frame o in the world: p_w = w_M_o * p_o
  Eigen::Vector3d size = Eigen::Vector3d(0.025, 0.0, 0.0);  ///< see the table above
  Material material;  ///< reflectance and shading
  std::shared_ptr<const Texture> texture;  ///< Rectangle only
  bool thin = false;   ///< may be thinner than a pixel: supersample every pixel of its footprint
  int tag_id = -1;     ///< AprilTag id of a tag rectangle (truth), else -1
  double tag_size = 0; ///< AprilTag black-border side, m (truth corners are ±tag_size/2)
};

/// One directional light (world frame).
struct Lighting {
  Eigen::Vector3d direction_w = Eigen::Vector3d(0.3, -0.5, 1.0).normalized();  ///< towards the light
  Eigen::Vector3d color_bgr = Eigen::Vector3d(1.0, 1.0, 1.0);                 ///< light intensity per channel
};

/// What a camera can see: primitives and the background colour.
struct Scene {
  std::vector<Primitive> primitives;  ///< the objects
  Eigen::Vector3d background_bgr = Eigen::Vector3d(0.25, 0.25, 0.25);  ///< where no object is hit
};

// -------------------------------------------------------------------------------------------
// Builders (validate their input and throw core::InvalidInput naming the field).

/// A named sphere of `radius` (m) at `center_w` (world frame), reflectance albedo_bgr.
Primitive makeSphere(const std::string& name, const Eigen::Vector3d& center_w, double radius,
                     const Eigen::Vector3d& albedo_bgr);
/// A named box of full `extents` (m) at pose w_M_o, reflectance albedo_bgr.
Primitive makeBox(const std::string& name, const Eigen::Isometry3d& w_M_o, const Eigen::Vector3d& extents,
                  const Eigen::Vector3d& albedo_bgr);
/// A named rectangle width x height (m) in the plane z = 0 of w_M_o, optionally textured.
Primitive makeRectangle(const std::string& name, const Eigen::Isometry3d& w_M_o, double width, double height,
                        const Eigen::Vector3d& albedo_bgr, std::shared_ptr<const Texture> texture = nullptr);
/// A named disc of `radius` (m) in the plane z = 0 of w_M_o.
Primitive makeDisc(const std::string& name, const Eigen::Isometry3d& w_M_o, double radius,
                   const Eigen::Vector3d& albedo_bgr);

/// An AprilTag tag36h11 code `id` whose black square has side `tag_size`, in the frame w_M_tag
/// (the simulator's tag frame: origin at the tag centre, x right and y down along the printed
/// code, z into the surface, i.e. away from a viewer who reads the code). This is NOT the frame
/// of vpDetectorAprilTag::getPose(), whose z points out of the tag: see simTag_M_vispTag().
/// The rectangle includes the one-cell white quiet ring (side 10/8 tag_size).
Primitive makeTag36h11(const std::string& name, int id, double tag_size, const Eigen::Isometry3d& w_M_tag);

/// The tag frame of vpDetectorAprilTag::getPose() (ViSP 3.5, default setZAlignedWithCameraAxis(false):
/// origin at the tag centre, x right and y UP along the printed code, z OUT of the tag towards the
/// viewer; the frame vision::AprilTagDetector's c_M_o and vision::TagOnTable::t_M_tag use)
/// expressed in the simulator's tag frame of makeTag36h11 (x right, y down, z into the surface):
/// a half turn about x, simTag_M_vispTag = Rx(π) = diag(1, -1, -1). A layout for a detector is
/// therefore  t_M_vispTag = t_M_simTag * simTag_M_vispTag();  feeding t_M_simTag directly mirrors
/// every tag's corners about its x axis and the PnP returns the plane seen from behind (a table
/// flipped by ~180°). Checked against ViSP by sim's renderer test and scenarios' observer test.
Eigen::Isometry3d simTag_M_vispTag();

/// The tag36h11 code image (10x10 cells incl. the white ring). Throws for an id
/// outside the family.
std::shared_ptr<const Texture> tag36h11Texture(int id);

/// Procedural value-noise texture (seeded): `octaves` layers of random grids (base_cells · 2^k
/// cells, amplitude persistence^k), bicubically upsampled, mixed around `mean_bgr` with relative
/// contrast `contrast`.
struct NoiseTextureParams {
  int resolution = 512;                                           ///< texels per side
  int octaves = 5;  ///< number of octaves
  int base_cells = 4;                                             ///< cells of the coarsest octave
  double contrast = 0.35;                                         ///< relative amplitude
  double persistence = 0.55;                                      ///< amplitude ratio of octave k+1 to k
  Eigen::Vector3d mean_bgr = Eigen::Vector3d(0.45, 0.5, 0.55);  ///< mean colour (BGR reflectance)
};
/// A seeded value-noise texture (procedural; see NoiseTextureParams).
std::shared_ptr<const Texture> makeNoiseTexture(const NoiseTextureParams& params, core::Rng& rng);

/// A checkerboard texture of `cells` x `cells` squares of colours a and b.
std::shared_ptr<const Texture> makeCheckerTexture(int cells, const Eigen::Vector3d& a_bgr,
                                                  const Eigen::Vector3d& b_bgr, int texels_per_cell = 8);

/// A dart (object z = flight direction, tip at +z, origin at the centre of mass): steel tip cone,
/// barrel cylinder, shaft, and two crossed flights. `name` is given to the barrel (truth).
std::vector<Primitive> makeDart(const std::string& name, const Eigen::Isometry3d& w_M_dart,
                                const Eigen::Vector3d& flight_bgr = Eigen::Vector3d(0.1, 0.1, 0.8));

/// Distractor blobs of a colour similar to a target (clutter): spheres with centres uniform in
/// the world box [min_w, max_w], radius uniform in [radius_min, radius_max], and albedo
/// colour_bgr + N(0, colour_jitter²) per channel (clamped to [0, 1]).
struct ClutterSettings {
  int count = 0;  ///< number of distractor blobs
  Eigen::Vector3d min_w = Eigen::Vector3d(-1.0, -1.0, 0.0);  ///< lower corner of the world box of the centres, m
  Eigen::Vector3d max_w = Eigen::Vector3d(1.0, 1.0, 1.0);  ///< upper corner of the world box of the centres, m
  double radius_min = 0.01,   ///< smallest blob radius, m
         radius_max = 0.03;   ///< largest blob radius, m
  Eigen::Vector3d colour_bgr = Eigen::Vector3d(0.1, 0.5, 0.95);  ///< mean colour of the blobs (BGR reflectance)
  double colour_jitter = 0.05;  ///< std of the per-channel colour around colour_bgr
};
/// Adds settings.count distractor spheres to the scene (seeded).
void addClutter(Scene& scene, const ClutterSettings& settings, core::Rng& rng);

// -------------------------------------------------------------------------------------------
// Ground truth.

/// What a perfect detector would report for one named primitive in one frame.
struct ObjectTruth {
  std::string name;  ///< name of the primitive
  Shape shape = Shape::Sphere;  ///< shape kind
  Eigen::Isometry3d w_M_o = Eigen::Isometry3d::Identity();  ///< at the frame's capture time
  /// Object frame in the camera frame at the capture time (p_c = c_M_o * p_o)
  Eigen::Isometry3d c_M_o = Eigen::Isometry3d::Identity();
  bool in_front = false;               ///< origin in front of the camera (Z > 0)
  bool in_image = false;               ///< projected origin inside the image
  Eigen::Vector2d center_px = Eigen::Vector2d::Zero();  ///< projection of the origin (distortion applied)
  // Spheres: the exact silhouette (72 projected points of the tangent circle, distortion applied)
  // and what ideal blob detectors would measure on it.
  /// Exact silhouette of a sphere: 72 projected points of the tangent circle (distortion applied), px
  std::vector<Eigen::Vector2d> outline_px;
  Eigen::Vector2d outline_centroid_px = Eigen::Vector2d::Zero();  ///< area centroid of the silhouette
  Eigen::Vector2d enclosing_center_px = Eigen::Vector2d::Zero();  ///< cv::minEnclosingCircle centre
  double enclosing_radius_px = 0.0;                               ///< cv::minEnclosingCircle radius
  double semi_major_px = 0.0,                                     ///< fitted silhouette ellipse semi-major axis, px
         semi_minor_px = 0.0;                                     ///< fitted silhouette ellipse semi-minor axis, px
  // Rectangles/discs/tags: corners (±a, ±b, 0) in the order (-,-), (+,-), (+,+), (-,+) with a, b
  // the half sizes (the black square's for tags); boxes: the 8 corners.
  std::vector<Eigen::Vector2d> corners_px;  ///< projected corners (rectangles, discs, tags: 4; boxes: 8), px
  int tag_id = -1;  ///< AprilTag id of a tag rectangle, else -1
  /// Fraction of the object's unoccluded footprint (pixel centres) that is visible in the frame;
  /// -1 when unknown (static objects hidden by moving ones are not re-counted).
  double visible_fraction = -1.0;
  int footprint_px = 0;  ///< pixels (centres) the object covers when nothing occludes it
};

}  // namespace viewline::sim
