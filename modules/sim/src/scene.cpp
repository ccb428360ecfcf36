#include "viewline/sim/scene.h"

#include <algorithm>
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::sim {

using core::InvalidInput;
using Eigen::Vector3d;

Eigen::Vector3d Texture::sample(double u, double v) const {
  const int w = image.cols, h = image.rows;
  if (nearest) {
    const int i = std::clamp(static_cast<int>(std::floor(u * w)), 0, w - 1);
    const int j = std::clamp(static_cast<int>(std::floor(v * h)), 0, h - 1);
    const cv::Vec3f& p = image.at<cv::Vec3f>(j, i);
    return {static_cast<double>(p[0]), static_cast<double>(p[1]), static_cast<double>(p[2])};
  }
  const double x = std::clamp(u * w - 0.5, 0.0, w - 1.0);
  const double y = std::clamp(v * h - 0.5, 0.0, h - 1.0);
  const int i0 = std::min(static_cast<int>(x), w - 1), j0 = std::min(static_cast<int>(y), h - 1);
  const int i1 = std::min(i0 + 1, w - 1), j1 = std::min(j0 + 1, h - 1);
  const double fx = x - i0, fy = y - j0;
  const cv::Vec3f& a = image.at<cv::Vec3f>(j0, i0);
  const cv::Vec3f& b = image.at<cv::Vec3f>(j0, i1);
  const cv::Vec3f& c = image.at<cv::Vec3f>(j1, i0);
  const cv::Vec3f& d = image.at<cv::Vec3f>(j1, i1);
  Vector3d out;
  for (int k = 0; k < 3; ++k) {
    out[k] = (1 - fy) * ((1 - fx) * static_cast<double>(a[k]) + fx * static_cast<double>(b[k])) +
             fy * ((1 - fx) * static_cast<double>(c[k]) + fx * static_cast<double>(d[k]));
  }
  return out;
}

namespace {
void requireColour(const Vector3d& c, const std::string& what) {
  core::requireFinite(c, what);
  if ((c.array() < 0.0).any() || (c.array() > 1.0).any()) {
    throw InvalidInput(what + " must lie in [0, 1] per channel (BGR reflectance)");
  }
}
void requirePose(const Eigen::Isometry3d& m, const std::string& what) {
  core::requireFinite(m.matrix(), what);
}
}  // namespace

Primitive makeSphere(const std::string& name, const Vector3d& center_w, double radius, const Vector3d& albedo_bgr) {
  core::requireFinite(center_w, "makeSphere '" + name + "': center");
  core::requirePositive(radius, "makeSphere '" + name + "': radius");
  requireColour(albedo_bgr, "makeSphere '" + name + "': albedo");
  Primitive p;
  p.name = name;
  p.shape = Shape::Sphere;
  p.w_M_o.translation() = center_w;
  p.size = Vector3d(radius, 0.0, 0.0);
  p.material.albedo_bgr = albedo_bgr;
  return p;
}

Primitive makeBox(const std::string& name, const Eigen::Isometry3d& w_M_o, const Vector3d& extents,
                  const Vector3d& albedo_bgr) {
  requirePose(w_M_o, "makeBox '" + name + "': pose");
  for (int i = 0; i < 3; ++i) core::requirePositive(extents[i], "makeBox '" + name + "': extents");
  requireColour(albedo_bgr, "makeBox '" + name + "': albedo");
  Primitive p;
  p.name = name;
  p.shape = Shape::Box;
  p.w_M_o = w_M_o;
  p.size = extents;
  p.material.albedo_bgr = albedo_bgr;
  return p;
}

Primitive makeRectangle(const std::string& name, const Eigen::Isometry3d& w_M_o, double width, double height,
                        const Vector3d& albedo_bgr, std::shared_ptr<const Texture> texture) {
  requirePose(w_M_o, "makeRectangle '" + name + "': pose");
  core::requirePositive(width, "makeRectangle '" + name + "': width");
  core::requirePositive(height, "makeRectangle '" + name + "': height");
  requireColour(albedo_bgr, "makeRectangle '" + name + "': albedo");
  Primitive p;
  p.name = name;
  p.shape = Shape::Rectangle;
  p.w_M_o = w_M_o;
  p.size = Vector3d(width, height, 0.0);
  p.material.albedo_bgr = albedo_bgr;
  p.texture = std::move(texture);
  return p;
}

Primitive makeDisc(const std::string& name, const Eigen::Isometry3d& w_M_o, double radius, const Vector3d& albedo_bgr) {
  requirePose(w_M_o, "makeDisc '" + name + "': pose");
  core::requirePositive(radius, "makeDisc '" + name + "': radius");
  requireColour(albedo_bgr, "makeDisc '" + name + "': albedo");
  Primitive p;
  p.name = name;
  p.shape = Shape::Disc;
  p.w_M_o = w_M_o;
  p.size = Vector3d(radius, 0.0, 0.0);
  p.material.albedo_bgr = albedo_bgr;
  return p;
}

std::shared_ptr<const Texture> tag36h11Texture(int id) {
  apriltag_family_t* family = tag36h11_create();
  if (id < 0 || static_cast<std::uint32_t>(id) >= family->ncodes) {
    const auto n = family->ncodes;
    tag36h11_destroy(family);
    std::ostringstream s;
    s << "tag36h11Texture: id " << id << " outside the family (0.." << n - 1 << ")";
    throw InvalidInput(s.str());
  }
  // The code image as apriltag_to_image() draws it: a one-cell white ring (for the normal
  // border), black elsewhere, white data bits at (bit_x, bit_y) inside the black border.
  const int n = family->total_width;
  const int ring = family->width_at_border + (family->reversed_border ? 0 : 2);
  const int ring_start = (n - ring) / 2;
  const int border_start = (n - family->width_at_border) / 2;
  cv::Mat code(n, n, CV_8U, cv::Scalar(0));
  for (int i = 0; i < ring - 1; ++i) {
    code.at<uchar>(ring_start, ring_start + i) = 255;
    code.at<uchar>(ring_start + i, n - 1 - ring_start) = 255;
    code.at<uchar>(n - ring_start - 1, ring_start + i + 1) = 255;
    code.at<uchar>(ring_start + 1 + i, ring_start) = 255;
  }
  const std::uint64_t word = family->codes[id];
  for (std::uint32_t i = 0; i < family->nbits; ++i) {
    if ((word >> (family->nbits - i - 1)) & 1u) {
      code.at<uchar>(static_cast<int>(family->bit_y[i]) + border_start, static_cast<int>(family->bit_x[i]) + border_start) = 255;
    }
  }
  auto tex = std::make_shared<Texture>();
  tex->nearest = true;
  tex->image = cv::Mat(n, n, CV_32FC3);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      // Printed paper: white 0.92, black 0.06 reflectance.
      const float v = code.at<uchar>(j, i) > 127 ? 0.92f : 0.06f;
      tex->image.at<cv::Vec3f>(j, i) = cv::Vec3f(v, v, v);
    }
  }
  tag36h11_destroy(family);
  return tex;
}

Primitive makeTag36h11(const std::string& name, int id, double tag_size, const Eigen::Isometry3d& w_M_tag) {
  core::requirePositive(tag_size, "makeTag36h11 '" + name + "': tag_size");
  // tag36h11: 8 cells between the outer edges of the black border, 10 with the white ring.
  Primitive p = makeRectangle(name, w_M_tag, tag_size * 10.0 / 8.0, tag_size * 10.0 / 8.0,
                              Vector3d(1.0, 1.0, 1.0), tag36h11Texture(id));
  p.tag_id = id;
  p.tag_size = tag_size;
  return p;
}

Eigen::Isometry3d simTag_M_vispTag() {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();  // Rx(π)
  return m;
}

std::shared_ptr<const Texture> makeNoiseTexture(const NoiseTextureParams& params, core::Rng& rng) {
  if (params.resolution < 2) throw InvalidInput("NoiseTextureParams.resolution must be >= 2");
  if (params.octaves < 1) throw InvalidInput("NoiseTextureParams.octaves must be >= 1");
  if (params.base_cells < 1) throw InvalidInput("NoiseTextureParams.base_cells must be >= 1");
  core::requireFinite(params.contrast, "NoiseTextureParams.contrast");
  core::requirePositive(params.persistence, "NoiseTextureParams.persistence");
  requireColour(params.mean_bgr, "NoiseTextureParams.mean_bgr");
  const int res = params.resolution;
  cv::Mat lum = cv::Mat::zeros(res, res, CV_32F);
  cv::Mat tint = cv::Mat::zeros(res, res, CV_32FC3);
  float amp = 1.0f, total = 0.0f;
  for (int o = 0; o < params.octaves; ++o) {
    const int cells = std::min(res, params.base_cells << o);
    cv::Mat grid(cells + 1, cells + 1, CV_32F), cgrid(cells + 1, cells + 1, CV_32FC3);
    for (int j = 0; j <= cells; ++j) {
      for (int i = 0; i <= cells; ++i) {
        grid.at<float>(j, i) = static_cast<float>(core::uniform(rng, -1.0, 1.0));
        cgrid.at<cv::Vec3f>(j, i) = cv::Vec3f(static_cast<float>(core::uniform(rng, -1.0, 1.0)),
                                              static_cast<float>(core::uniform(rng, -1.0, 1.0)),
                                              static_cast<float>(core::uniform(rng, -1.0, 1.0)));
      }
    }
    cv::Mat up, cup;
    cv::resize(grid, up, cv::Size(res, res), 0, 0, cv::INTER_CUBIC);
    cv::resize(cgrid, cup, cv::Size(res, res), 0, 0, cv::INTER_CUBIC);
    lum += amp * up;
    tint += 0.3f * amp * cup;
    total += amp;
    amp *= static_cast<float>(params.persistence);
  }
  auto tex = std::make_shared<Texture>();
  tex->image = cv::Mat(res, res, CV_32FC3);
  const auto c = static_cast<float>(params.contrast);
  for (int j = 0; j < res; ++j) {
    for (int i = 0; i < res; ++i) {
      const float l = lum.at<float>(j, i) / total;
      const cv::Vec3f& tn = tint.at<cv::Vec3f>(j, i);
      cv::Vec3f& out = tex->image.at<cv::Vec3f>(j, i);
      for (int k = 0; k < 3; ++k) {
        const float m = static_cast<float>(params.mean_bgr[k]);
        out[k] = std::clamp(m * (1.0f + c * (l + tn[k] / total)), 0.0f, 1.0f);
      }
    }
  }
  return tex;
}

std::shared_ptr<const Texture> makeCheckerTexture(int cells, const Vector3d& a_bgr, const Vector3d& b_bgr,
                                                  int texels_per_cell) {
  if (cells < 1) throw InvalidInput("makeCheckerTexture: cells must be >= 1");
  if (texels_per_cell < 1) throw InvalidInput("makeCheckerTexture: texels_per_cell must be >= 1");
  requireColour(a_bgr, "makeCheckerTexture: colour a");
  requireColour(b_bgr, "makeCheckerTexture: colour b");
  auto tex = std::make_shared<Texture>();
  tex->nearest = true;
  const int n = cells * texels_per_cell;
  tex->image = cv::Mat(n, n, CV_32FC3);
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const Vector3d& c = ((i / texels_per_cell + j / texels_per_cell) % 2 == 0) ? a_bgr : b_bgr;
      tex->image.at<cv::Vec3f>(j, i) =
          cv::Vec3f(static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2]));
    }
  }
  return tex;
}

std::vector<Primitive> makeDart(const std::string& name, const Eigen::Isometry3d& w_M_dart, const Vector3d& flight_bgr) {
  requirePose(w_M_dart, "makeDart '" + name + "': pose");
  requireColour(flight_bgr, "makeDart '" + name + "': flight colour");
  auto at = [&](double z) {
    Eigen::Isometry3d d_M_p = Eigen::Isometry3d::Identity();
    d_M_p.translation() = Vector3d(0.0, 0.0, z);
    return w_M_dart * d_M_p;
  };
  std::vector<Primitive> parts;
  Primitive barrel;  // the named part: its frame is the dart frame (origin at the barrel's rear)
  barrel.name = name;
  barrel.shape = Shape::Cylinder;
  barrel.w_M_o = w_M_dart;
  barrel.size = Vector3d(0.0035, 0.0, 0.05);
  barrel.material.albedo_bgr = Vector3d(0.55, 0.55, 0.6);
  barrel.thin = true;
  parts.push_back(barrel);
  Primitive tip;
  tip.shape = Shape::Cone;
  tip.w_M_o = at(0.05);
  tip.size = Vector3d(0.0012, 0.0, 0.035);
  tip.material.albedo_bgr = Vector3d(0.8, 0.8, 0.8);
  tip.thin = true;
  parts.push_back(tip);
  Primitive shaft;
  shaft.shape = Shape::Cylinder;
  shaft.w_M_o = at(-0.045);
  shaft.size = Vector3d(0.002, 0.0, 0.045);
  shaft.material.albedo_bgr = Vector3d(0.1, 0.1, 0.1);
  shaft.thin = true;
  parts.push_back(shaft);
  for (int f = 0; f < 2; ++f) {  // two crossed flights containing the body axis
    Primitive flight;
    flight.shape = Shape::Rectangle;
    Eigen::Isometry3d d_M_f = Eigen::Isometry3d::Identity();
    d_M_f.linear() = core::rotation(Vector3d::UnitZ(), f * core::kPi / 2.0) * core::rotation(Vector3d::UnitX(), core::kPi / 2.0);
    d_M_f.translation() = Vector3d(0.0, 0.0, -0.05);
    flight.w_M_o = w_M_dart * d_M_f;
    flight.size = Vector3d(0.03, 0.035, 0.0);  // 3 cm across, 3.5 cm along the body
    flight.material.albedo_bgr = flight_bgr;
    flight.thin = true;
    parts.push_back(flight);
  }
  return parts;
}

void addClutter(Scene& scene, const ClutterSettings& s, core::Rng& rng) {
  if (s.count < 0) throw InvalidInput("ClutterSettings.count must be >= 0");
  if (s.count == 0) return;
  core::requirePositive(s.radius_min, "ClutterSettings.radius_min");
  core::requirePositive(s.radius_max, "ClutterSettings.radius_max");
  if (s.radius_max < s.radius_min) throw InvalidInput("ClutterSettings.radius_max < radius_min");
  core::requireFinite(s.min_w, "ClutterSettings.min_w");
  core::requireFinite(s.max_w, "ClutterSettings.max_w");
  if ((s.max_w.array() < s.min_w.array()).any()) throw InvalidInput("ClutterSettings.max_w < min_w");
  requireColour(s.colour_bgr, "ClutterSettings.colour_bgr");
  core::requireFinite(s.colour_jitter, "ClutterSettings.colour_jitter");
  for (int i = 0; i < s.count; ++i) {
    Vector3d c;
    for (int k = 0; k < 3; ++k) c[k] = core::uniform(rng, s.min_w[k], s.max_w[k]);
    const double r = core::uniform(rng, s.radius_min, s.radius_max);
    Vector3d colour = s.colour_bgr;
    for (int k = 0; k < 3; ++k) colour[k] = std::clamp(colour[k] + core::gaussian(rng, s.colour_jitter), 0.0, 1.0);
    scene.primitives.push_back(makeSphere("", c, r, colour));
  }
}

}  // namespace viewline::sim
