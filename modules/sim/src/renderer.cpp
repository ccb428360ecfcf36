#include "viewline/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <list>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::sim {

using core::InvalidInput;
using Eigen::Vector3d;

namespace {

constexpr double kNear = 1e-4;  // m: nothing closer to the camera centre is drawn
constexpr double kInf = std::numeric_limits<double>::infinity();

// Coefficient of ViSP's forward (meter -> pixel) model: vpMeterPixelConversion applies kud,
// u = u0 + px x (1 + kud (x² + y²)) (vpPixelMeterConversion applies kdu the other way).
double forwardDistortion(const vpCameraParameters& k) {
  return k.get_projModel() == vpCameraParameters::perspectiveProjWithDistortion ? k.get_kud() : 0.0;
}

// Smallest rho >= 0 with rho (1 + kd rho²) = rd; false when the model never reaches rd.
bool undistortRadius(double rd, double kd, double& rho) {
  if (kd == 0.0 || rd == 0.0) {
    rho = rd;
    return true;
  }
  if (kd < 0.0) {  // the forward map peaks at rho = 1/sqrt(-3 kd)
    const double rmax = 1.0 / std::sqrt(-3.0 * kd);
    if (rd > rmax * (1.0 + kd * rmax * rmax)) return false;
  }
  double r = rd;  // Newton converges monotonically from rd (concave for kd<0, convex for kd>0)
  for (int i = 0; i < 50; ++i) {
    const double f = r * (1.0 + kd * r * r) - rd;
    const double dr = f / (1.0 + 3.0 * kd * r * r);
    r -= dr;
    if (std::abs(dr) <= 1e-16 * (1.0 + r)) break;
  }
  rho = r;
  return true;
}

struct Intrinsics {
  double px, py, u0, v0, kd;
  explicit Intrinsics(const core::Camera& c)
      : px(c.intrinsics.get_px()), py(c.intrinsics.get_py()), u0(c.intrinsics.get_u0()),
        v0(c.intrinsics.get_v0()), kd(forwardDistortion(c.intrinsics)) {}
  Eigen::Vector2d toPixel(double x, double y) const {
    const double s = 1.0 + kd * (x * x + y * y);
    return {u0 + px * x * s, v0 + py * y * s};
  }
  Eigen::Vector2d toNormalized(double u, double v) const {
    const double xd = (u - u0) / px, yd = (v - v0) / py;
    const double rd = std::hypot(xd, yd);
    double rho = 0.0;
    if (!undistortRadius(rd, kd, rho)) return {std::nan(""), std::nan("")};
    const double s = rd > 0.0 ? rho / rd : 1.0;
    return {xd * s, yd * s};
  }
};

// Normalised ray coordinates at pixel corners ((i-½, j-½), (w+1) x (h+1)) and centres (w x h).
struct RayGrid {
  int w = 0, h = 0;
  std::vector<double> corner, center;
};

RayGrid makeRayGrid(const core::Camera& cam) {
  const Intrinsics k(cam);
  RayGrid g;
  g.w = static_cast<int>(cam.width);
  g.h = static_cast<int>(cam.height);
  g.corner.resize(2 * static_cast<std::size_t>(g.w + 1) * static_cast<std::size_t>(g.h + 1));
  g.center.resize(2 * static_cast<std::size_t>(g.w) * static_cast<std::size_t>(g.h));
  for (int j = 0; j <= g.h; ++j) {
    for (int i = 0; i <= g.w; ++i) {
      const Eigen::Vector2d xy = k.toNormalized(i - 0.5, j - 0.5);
      const std::size_t idx = 2 * (static_cast<std::size_t>(j) * static_cast<std::size_t>(g.w + 1) + static_cast<std::size_t>(i));
      g.corner[idx] = xy.x();
      g.corner[idx + 1] = xy.y();
      if (i < g.w && j < g.h) {
        const Eigen::Vector2d c = k.toNormalized(i, j);
        const std::size_t cdx = 2 * (static_cast<std::size_t>(j) * static_cast<std::size_t>(g.w) + static_cast<std::size_t>(i));
        g.center[cdx] = c.x();
        g.center[cdx + 1] = c.y();
      }
    }
  }
  return g;
}

struct Prepared {
  Shape shape = Shape::Sphere;
  Eigen::Matrix3d c_R_o, o_R_c;
  Vector3d c_origin, o_eye, size;
  Material material;
  const Texture* texture = nullptr;
  bool thin = false;
  bool named = false;
  cv::Rect bbox;
};

struct Hit {
  double t = kInf;
  Vector3d n = Vector3d::UnitZ();  // camera frame
  double u = 0.0, v = 0.0;
};

struct Light {
  Vector3d dir_c, color;
};

Prepared prepare(const Primitive& p, const Eigen::Isometry3d& c_M_w) {
  Prepared r;
  const Eigen::Isometry3d c_M_o = c_M_w * p.w_M_o;
  r.shape = p.shape;
  r.c_R_o = c_M_o.linear();
  r.o_R_c = r.c_R_o.transpose();
  r.c_origin = c_M_o.translation();
  r.o_eye = -(r.o_R_c * r.c_origin);
  r.size = p.size;
  r.material = p.material;
  r.texture = p.texture.get();
  r.thin = p.thin;
  r.named = !p.name.empty();
  return r;
}

inline bool intersect(const Prepared& p, const Vector3d& d, double tmax, Hit& h) {
  switch (p.shape) {
    case Shape::Sphere: {
      const Vector3d& C = p.c_origin;
      const double r = p.size.x();
      const double a = d.squaredNorm(), b = d.dot(C), c = C.squaredNorm() - r * r;
      const double disc = b * b - a * c;
      if (!(disc >= 0.0)) return false;
      const double sq = std::sqrt(disc);
      double t = (b - sq) / a;
      if (t <= kNear) t = (b + sq) / a;
      if (t <= kNear || t >= tmax) return false;
      h.t = t;
      h.n = (t * d - C) / r;
      return true;
    }
    case Shape::Box: {
      const Vector3d e = p.o_R_c * d;
      const Vector3d& o = p.o_eye;
      double t0 = -kInf, t1 = kInf;
      int axis = -1;
      for (int i = 0; i < 3; ++i) {
        const double hs = 0.5 * p.size[i];
        if (std::abs(e[i]) < 1e-300) {
          if (std::abs(o[i]) > hs) return false;
          continue;
        }
        double ta = (-hs - o[i]) / e[i], tb = (hs - o[i]) / e[i];
        if (ta > tb) std::swap(ta, tb);
        if (ta > t0) {
          t0 = ta;
          axis = i;
        }
        t1 = std::min(t1, tb);
        if (t0 > t1) return false;
      }
      if (axis < 0 || t0 <= kNear || t0 >= tmax) return false;
      Vector3d n_o = Vector3d::Zero();
      n_o[axis] = e[axis] > 0.0 ? -1.0 : 1.0;
      h.t = t0;
      h.n = p.c_R_o * n_o;
      return true;
    }
    case Shape::Cylinder:
    case Shape::Cone: {
      const Vector3d e = p.o_R_c * d;
      const Vector3d& o = p.o_eye;
      const double R = p.size.x(), L = p.size.z();
      double best = tmax;
      Vector3d n_o;
      bool hit = false;
      if (p.shape == Shape::Cylinder) {
        const double a = e.x() * e.x() + e.y() * e.y();
        if (a > 1e-300) {
          const double b = o.x() * e.x() + o.y() * e.y();
          const double c = o.x() * o.x() + o.y() * o.y() - R * R;
          const double disc = b * b - a * c;
          if (disc >= 0.0) {
            const double t = (-b - std::sqrt(disc)) / a;
            const double z = o.z() + t * e.z();
            if (t > kNear && t < best && z >= 0.0 && z <= L) {
              best = t;
              hit = true;
              n_o = Vector3d(o.x() + t * e.x(), o.y() + t * e.y(), 0.0) / R;
            }
          }
        }
      } else {
        const double k2 = (R / L) * (R / L);
        const double w0 = L - o.z();
        const double A = e.x() * e.x() + e.y() * e.y() - k2 * e.z() * e.z();
        const double B = o.x() * e.x() + o.y() * e.y() + k2 * w0 * e.z();
        const double C = o.x() * o.x() + o.y() * o.y() - k2 * w0 * w0;
        double roots[2];
        int nr = 0;
        if (std::abs(A) > 1e-300) {
          const double disc = B * B - A * C;
          if (disc >= 0.0) {
            const double sq = std::sqrt(disc);
            roots[0] = (-B - sq) / A;
            roots[1] = (-B + sq) / A;
            if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
            nr = 2;
          }
        } else if (std::abs(B) > 1e-300) {
          roots[0] = -C / (2.0 * B);
          nr = 1;
        }
        for (int i = 0; i < nr; ++i) {
          const double t = roots[i];
          const double z = o.z() + t * e.z();
          if (t > kNear && t < best && z >= 0.0 && z <= L) {
            best = t;
            hit = true;
            n_o = Vector3d(o.x() + t * e.x(), o.y() + t * e.y(), k2 * (L - z)).normalized();
            break;
          }
        }
      }
      if (std::abs(e.z()) > 1e-300) {  // caps: z = 0 (both), z = L (cylinder)
        const int caps = p.shape == Shape::Cylinder ? 2 : 1;
        for (int c = 0; c < caps; ++c) {
          const double zc = c == 0 ? 0.0 : L;
          const double t = (zc - o.z()) / e.z();
          if (t > kNear && t < best) {
            const double x = o.x() + t * e.x(), y = o.y() + t * e.y();
            if (x * x + y * y <= R * R) {
              best = t;
              hit = true;
              n_o = Vector3d(0.0, 0.0, c == 0 ? -1.0 : 1.0);
            }
          }
        }
      }
      if (!hit) return false;
      h.t = best;
      h.n = p.c_R_o * n_o;
      return true;
    }
    case Shape::Rectangle:
    case Shape::Disc: {
      const Vector3d e = p.o_R_c * d;
      const Vector3d& o = p.o_eye;
      if (std::abs(e.z()) < 1e-300) return false;
      const double t = -o.z() / e.z();
      if (!(t > kNear) || t >= tmax) return false;
      const double x = o.x() + t * e.x(), y = o.y() + t * e.y();
      if (p.shape == Shape::Rectangle) {
        if (std::abs(x) > 0.5 * p.size.x() || std::abs(y) > 0.5 * p.size.y()) return false;
        h.u = x / p.size.x() + 0.5;
        h.v = y / p.size.y() + 0.5;
      } else if (x * x + y * y > p.size.x() * p.size.x()) {
        return false;
      }
      h.t = t;
      h.n = p.c_R_o.col(2);
      return true;
    }
  }
  return false;
}

inline Vector3d shade(const Prepared& p, const Hit& h, const Vector3d& d, const Light& light) {
  Vector3d albedo = p.material.albedo_bgr;
  if (p.texture != nullptr) albedo = albedo.cwiseProduct(p.texture->sample(h.u, h.v));
  const Vector3d lit = albedo.cwiseProduct(light.color);
  if (p.material.unlit) return lit;
  Vector3d n = h.n;
  if (n.dot(d) > 0.0) n = -n;
  const double lambert = std::max(0.0, n.dot(light.dir_c));
  return lit * (p.material.ambient + (1.0 - p.material.ambient) * lambert);
}

// Nearest hit closer than tmax among prims: its index (or -1), colour and depth.
// Only primitives whose pixel box holds pixel (px, py) are tested (boxes have a 2 px margin, so
// this is exact for sub-samples and corners of that pixel).
inline int trace(const std::vector<const Prepared*>& prims, int px, int py, double x, double y, double tmax,
                 const Light& light, Vector3d& colour, double* depth) {
  if (!std::isfinite(x) || !std::isfinite(y)) return -1;
  const Vector3d d(x, y, 1.0);
  const cv::Point pixel(px, py);
  Hit best, h;
  int id = -1;
  for (std::size_t i = 0; i < prims.size(); ++i) {
    if (!prims[i]->bbox.contains(pixel)) continue;
    if (intersect(*prims[i], d, tmax, h)) {
      best = h;
      tmax = h.t;
      id = static_cast<int>(i);
    }
  }
  if (id >= 0) {
    colour = shade(*prims[static_cast<std::size_t>(id)], best, d, light);
    if (depth != nullptr) *depth = best.t;
  }
  return id;
}

struct Base {
  const cv::Mat* bgr8 = nullptr;     // CV_8UC3 or null (-> background colour)
  const cv::Mat* depth = nullptr;    // CV_32F or null (-> infinity)
  Vector3d background = Vector3d::Zero();
  Vector3d colour(int i, int j) const {
    if (bgr8 == nullptr) return background;
    const cv::Vec3b& p = bgr8->at<cv::Vec3b>(j, i);
    return Vector3d(p[0], p[1], p[2]) / 255.0;
  }
  double depthAt(int i, int j) const {
    if (depth == nullptr) return kInf;
    return static_cast<double>(depth->at<float>(j, i));
  }
};

// Adds weight x colour of every pixel of r (row-major over r) to acc; optionally writes the
// depth of the centre sample to depth_out (CV_32F, full image).
void renderRegion(const cv::Rect& r, const std::vector<const Prepared*>& prims, bool supersample_all,
                  const RayGrid& g, const Base& base, const Light& light, const RenderSettings& s,
                  double weight, double* acc, cv::Mat* depth_out) {
  const int n = std::max(1, s.supersampling);
  const std::size_t W1 = static_cast<std::size_t>(g.w + 1);
  const std::size_t cols = static_cast<std::size_t>(r.width + 1);
  std::vector<int> id_top(cols), id_bot(cols);
  std::vector<Vector3d> col_top(cols), col_bot(cols);
  auto cornerRow = [&](int j, std::vector<int>& ids, std::vector<Vector3d>& colours) {
    for (int i = r.x; i <= r.x + r.width; ++i) {
      const std::size_t k = 2 * (static_cast<std::size_t>(j) * W1 + static_cast<std::size_t>(i));
      const double bd = base.depthAt(std::min(i, g.w - 1), std::min(j, g.h - 1));
      const auto a = static_cast<std::size_t>(i - r.x);
      ids[a] = prims.empty() ? -1
                             : trace(prims, std::min(i, g.w - 1), std::min(j, g.h - 1), g.corner[k], g.corner[k + 1],
                                     bd, light, colours[a], nullptr);
    }
  };
  cornerRow(r.y, id_top, col_top);
  for (int j = r.y; j < r.y + r.height; ++j) {
    cornerRow(j + 1, id_bot, col_bot);
    for (int i = r.x; i < r.x + r.width; ++i) {
      const auto a = static_cast<std::size_t>(i - r.x);
      const double bd = base.depthAt(i, j);
      const int id = id_top[a];
      bool uniform = !supersample_all && id_top[a + 1] == id && id_bot[a] == id && id_bot[a + 1] == id;
      if (uniform && id >= 0) {
        const Vector3d lo = col_top[a].cwiseMin(col_top[a + 1]).cwiseMin(col_bot[a]).cwiseMin(col_bot[a + 1]);
        const Vector3d hi = col_top[a].cwiseMax(col_top[a + 1]).cwiseMax(col_bot[a]).cwiseMax(col_bot[a + 1]);
        uniform = (hi - lo).maxCoeff() < s.edge_threshold;
      }
      Vector3d c;
      double dep = bd;
      const std::size_t cidx = 2 * (static_cast<std::size_t>(j) * static_cast<std::size_t>(g.w) + static_cast<std::size_t>(i));
      if (uniform) {
        if (id < 0) {
          c = base.colour(i, j);
        } else if (trace(prims, i, j, g.center[cidx], g.center[cidx + 1], bd, light, c, &dep) < 0) {
          c = base.colour(i, j);
        }
      } else {
        const std::size_t k00 = 2 * (static_cast<std::size_t>(j) * W1 + static_cast<std::size_t>(i));
        const std::size_t k01 = k00 + 2 * W1;
        const double x00 = g.corner[k00], y00 = g.corner[k00 + 1], x10 = g.corner[k00 + 2], y10 = g.corner[k00 + 3];
        const double x01 = g.corner[k01], y01 = g.corner[k01 + 1], x11 = g.corner[k01 + 2], y11 = g.corner[k01 + 3];
        const Vector3d bc = base.colour(i, j);
        Vector3d sum = Vector3d::Zero(), sc;
        for (int sy = 0; sy < n; ++sy) {
          const double fy = (sy + 0.5) / n;
          for (int sx = 0; sx < n; ++sx) {
            const double fx = (sx + 0.5) / n;
            const double x = (1 - fy) * ((1 - fx) * x00 + fx * x10) + fy * ((1 - fx) * x01 + fx * x11);
            const double y = (1 - fy) * ((1 - fx) * y00 + fx * y10) + fy * ((1 - fx) * y01 + fx * y11);
            sum += trace(prims, i, j, x, y, bd, light, sc, nullptr) >= 0 ? sc : bc;
          }
        }
        c = sum / (n * n);
        if (depth_out != nullptr) trace(prims, i, j, g.center[cidx], g.center[cidx + 1], bd, light, sc, &dep);
      }
      double* out = acc + 3 * (static_cast<std::size_t>(j - r.y) * static_cast<std::size_t>(r.width) + a);
      out[0] += weight * c[0];
      out[1] += weight * c[1];
      out[2] += weight * c[2];
      if (depth_out != nullptr) depth_out->at<float>(j, i) = static_cast<float>(dep);
    }
    std::swap(id_top, id_bot);
    std::swap(col_top, col_bot);
  }
}

// renderRegion over horizontal bands of r in parallel (cv::parallel_for_): every pixel is
// computed independently from read-only inputs, so the result does not depend on the threads.
void renderRegionParallel(const cv::Rect& r, const std::vector<const Prepared*>& prims, bool supersample_all,
                          const RayGrid& g, const Base& base, const Light& light, const RenderSettings& s,
                          double weight, double* acc, cv::Mat* depth_out) {
  constexpr int kMinPixels = 16384;
  constexpr int kBandRows = 16;
  if (r.area() < kMinPixels || r.height < 2 * kBandRows) {
    renderRegion(r, prims, supersample_all, g, base, light, s, weight, acc, depth_out);
    return;
  }
  const int bands = (r.height + kBandRows - 1) / kBandRows;
  cv::parallel_for_(cv::Range(0, bands), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int y0 = r.y + b * kBandRows;
      const cv::Rect band(r.x, y0, r.width, std::min(kBandRows, r.y + r.height - y0));
      double* band_acc = acc + 3 * static_cast<std::size_t>(y0 - r.y) * static_cast<std::size_t>(r.width);
      renderRegion(band, prims, supersample_all, g, base, light, s, weight, band_acc, depth_out);
    }
  });
}

// Pixel centres of r covered by each named primitive (footprint) and where it is the nearest
// surface (visible), given the base depth.
void countCoverage(const cv::Rect& r, const std::vector<const Prepared*>& prims, const RayGrid& g,
                   const Base& base, std::vector<int>& footprint, std::vector<int>& visible) {
  Hit h;
  for (int j = r.y; j < r.y + r.height; ++j) {
    for (int i = r.x; i < r.x + r.width; ++i) {
      const std::size_t cidx = 2 * (static_cast<std::size_t>(j) * static_cast<std::size_t>(g.w) + static_cast<std::size_t>(i));
      const double x = g.center[cidx], y = g.center[cidx + 1];
      if (!std::isfinite(x) || !std::isfinite(y)) continue;
      const Vector3d d(x, y, 1.0);
      double tmax = base.depthAt(i, j);
      int nearest = -1;
      for (std::size_t k = 0; k < prims.size(); ++k) {
        if (!intersect(*prims[k], d, kInf, h)) continue;
        if (prims[k]->named) ++footprint[k];
        if (h.t < tmax) {
          tmax = h.t;
          nearest = static_cast<int>(k);
        }
      }
      if (nearest >= 0 && prims[static_cast<std::size_t>(nearest)]->named) ++visible[static_cast<std::size_t>(nearest)];
    }
  }
}

// Pixel bounding box of normalised-plane rectangle [xmin, xmax] x [ymin, ymax] (boundary sampled
// through the distortion model, 2 px margin), clipped to the image.
cv::Rect pixelBox(double xmin, double xmax, double ymin, double ymax, const Intrinsics& k, int w, int h) {
  const cv::Rect full(0, 0, w, h);
  if (k.kd < 0.0) {  // barrel distortion folds rays beyond rmax back: stay conservative there
    const double rmax2 = 1.0 / (-3.0 * k.kd);
    const double r2 = std::max(xmin * xmin, xmax * xmax) + std::max(ymin * ymin, ymax * ymax);
    if (r2 >= 0.98 * rmax2) return full;
  }
  double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
  constexpr int kSteps = 8;
  for (int e = 0; e < 4; ++e) {
    for (int s = 0; s <= kSteps; ++s) {
      const double f = static_cast<double>(s) / kSteps;
      double x = 0.0, y = 0.0;
      switch (e) {
        case 0: x = xmin + f * (xmax - xmin); y = ymin; break;
        case 1: x = xmin + f * (xmax - xmin); y = ymax; break;
        case 2: x = xmin; y = ymin + f * (ymax - ymin); break;
        default: x = xmax; y = ymin + f * (ymax - ymin); break;
      }
      const Eigen::Vector2d uv = k.toPixel(x, y);
      umin = std::min(umin, uv.x());
      umax = std::max(umax, uv.x());
      vmin = std::min(vmin, uv.y());
      vmax = std::max(vmax, uv.y());
    }
  }
  const double lim = 4.0 * (w + h);
  umin = std::clamp(umin, -lim, lim);
  umax = std::clamp(umax, -lim, lim);
  vmin = std::clamp(vmin, -lim, lim);
  vmax = std::clamp(vmax, -lim, lim);
  const int x0 = static_cast<int>(std::floor(umin)) - 2, x1 = static_cast<int>(std::ceil(umax)) + 3;
  const int y0 = static_cast<int>(std::floor(vmin)) - 2, y1 = static_cast<int>(std::ceil(vmax)) + 3;
  return cv::Rect(x0, y0, x1 - x0, y1 - y0) & full;
}

// Conservative pixel bounding box of a primitive (empty when wholly behind the camera): the
// projection of its sphere (spheres) or of the corners of its object-frame bounding box (others;
// the object is convex, so its image lies in the hull of the projected corners).
cv::Rect projectedBox(const Prepared& p, const Intrinsics& k, int w, int h) {
  const cv::Rect full(0, 0, w, h);
  double xmin = kInf, xmax = -kInf, ymin = kInf, ymax = -kInf;
  auto add = [&](const Vector3d& q) {
    xmin = std::min(xmin, q.x() / q.z());
    xmax = std::max(xmax, q.x() / q.z());
    ymin = std::min(ymin, q.y() / q.z());
    ymax = std::max(ymax, q.y() / q.z());
  };
  if (p.shape == Shape::Sphere) {
    const Vector3d& C = p.c_origin;
    const double R = p.size.x();
    if (C.z() + R <= kNear) return {};
    if (C.z() - R <= 1e-3) return full;
    for (double sz : {-R, R}) {
      for (double sx : {-R, R}) {
        for (double sy : {-R, R}) add(C + Vector3d(sx, sy, sz));
      }
    }
    return pixelBox(xmin, xmax, ymin, ymax, k, w, h);
  }
  Vector3d lo, hi;
  switch (p.shape) {
    case Shape::Box: lo = -0.5 * p.size; hi = 0.5 * p.size; break;
    case Shape::Cylinder:
    case Shape::Cone:
      lo = Vector3d(-p.size.x(), -p.size.x(), 0.0);
      hi = Vector3d(p.size.x(), p.size.x(), p.size.z());
      break;
    case Shape::Rectangle:
      lo = Vector3d(-0.5 * p.size.x(), -0.5 * p.size.y(), 0.0);
      hi = -lo;
      break;
    default:  // Disc
      lo = Vector3d(-p.size.x(), -p.size.x(), 0.0);
      hi = -lo;
      break;
  }
  int behind = 0, near = 0;
  Vector3d corners[8];
  for (int i = 0; i < 8; ++i) {
    const Vector3d q_o((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
    corners[i] = p.c_R_o * q_o + p.c_origin;
    if (corners[i].z() <= kNear) ++behind;
    if (corners[i].z() <= 1e-3) ++near;
  }
  if (behind == 8) return {};
  if (near > 0) return full;
  for (const auto& c : corners) add(c);
  return pixelBox(xmin, xmax, ymin, ymax, k, w, h);
}

void accToImage(const std::vector<double>& acc, const cv::Rect& r, cv::Mat& img) {
  for (int j = 0; j < r.height; ++j) {
    auto* row = img.ptr<cv::Vec3b>(r.y + j) + r.x;
    const double* a = acc.data() + 3 * static_cast<std::size_t>(j) * static_cast<std::size_t>(r.width);
    for (int i = 0; i < r.width; ++i) {
      for (int c = 0; c < 3; ++c) row[i][c] = cv::saturate_cast<uchar>(255.0 * a[3 * i + c]);
    }
  }
}

std::vector<cv::Rect> mergeRects(std::vector<cv::Rect> rects) {
  rects.erase(std::remove_if(rects.begin(), rects.end(), [](const cv::Rect& r) { return r.area() <= 0; }), rects.end());
  bool merged = true;
  while (merged) {
    merged = false;
    for (std::size_t a = 0; a < rects.size() && !merged; ++a) {
      for (std::size_t b = a + 1; b < rects.size(); ++b) {
        if ((rects[a] & rects[b]).area() > 0) {
          rects[a] = rects[a] | rects[b];
          rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(b));
          merged = true;
          break;
        }
      }
    }
  }
  return rects;
}

Light lightFor(const Lighting& l, const Eigen::Isometry3d& c_M_w) {
  return {(c_M_w.linear() * l.direction_w).normalized(), l.color_bgr};
}

void checkCamera(const core::Camera& camera) {
  if (camera.width == 0 || camera.height == 0) {
    throw InvalidInput("Renderer: camera '" + camera.name + "' has zero width or height");
  }
  core::requirePositive(camera.intrinsics.get_px(), "Renderer: camera '" + camera.name + "' px");
  core::requirePositive(camera.intrinsics.get_py(), "Renderer: camera '" + camera.name + "' py");
  core::requireFinite(camera.c_M_w.matrix(), "Renderer: camera '" + camera.name + "' c_M_w");
}

struct CameraKey {
  double v[24] = {};
  unsigned w = 0, h = 0;
  bool operator==(const CameraKey& o) const {
    return w == o.w && h == o.h && std::memcmp(v, o.v, sizeof(v)) == 0;
  }
};

CameraKey intrinsicsKey(const core::Camera& c) {
  CameraKey k;
  k.w = c.width;
  k.h = c.height;
  k.v[0] = c.intrinsics.get_px();
  k.v[1] = c.intrinsics.get_py();
  k.v[2] = c.intrinsics.get_u0();
  k.v[3] = c.intrinsics.get_v0();
  k.v[4] = forwardDistortion(c.intrinsics);
  return k;
}

// FNV-1a over the static scene's content: a world destroyed and another allocated at the same
// address must not reuse the cached layer.
std::uint64_t sceneHash(const Scene& scene) {
  std::uint64_t h = 1469598103934665603ULL;
  auto mix = [&h](const void* data, std::size_t n) {
    const auto* b = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) {
      h ^= b[i];
      h *= 1099511628211ULL;
    }
  };
  mix(scene.background_bgr.data(), 3 * sizeof(double));
  for (const Primitive& p : scene.primitives) {
    const int shape = static_cast<int>(p.shape);
    mix(&shape, sizeof(shape));
    mix(p.w_M_o.matrix().data(), 16 * sizeof(double));
    mix(p.size.data(), 3 * sizeof(double));
    mix(p.material.albedo_bgr.data(), 3 * sizeof(double));
    mix(&p.material.ambient, sizeof(double));
    const Texture* t = p.texture.get();
    mix(&t, sizeof(t));
  }
  return h;
}

CameraKey fullKey(const core::Camera& c, const World* world, std::uint64_t version, const Lighting& l) {
  CameraKey k = intrinsicsKey(c);
  const Eigen::Matrix4d m = c.c_M_w.matrix();
  for (int i = 0; i < 12; ++i) k.v[5 + i] = m(i % 3, i / 3);
  k.v[17] = static_cast<double>(reinterpret_cast<std::uintptr_t>(world));
  const std::uint64_t content = sceneHash(world->staticScene()) ^ (version * 0x9E3779B97F4A7C15ULL);
  std::memcpy(&k.v[18], &content, sizeof(content));
  for (int i = 0; i < 3; ++i) {
    k.v[19 + i] = l.direction_w[i];
  }
  k.v[22] = l.color_bgr.sum();
  k.v[23] = l.color_bgr[0] - l.color_bgr[2];
  return k;
}

}  // namespace

// ----------------------------------------------------------------------------------------------

Eigen::Vector2d undistortExact(const core::Camera& camera, const Eigen::Vector2d& uv) {
  return Intrinsics(camera).toNormalized(uv.x(), uv.y());
}

ObjectTruth describe(const Primitive& prim, const core::Camera& camera) {
  ObjectTruth t;
  t.name = prim.name;
  t.shape = prim.shape;
  t.w_M_o = prim.w_M_o;
  t.c_M_o = camera.c_M_w * prim.w_M_o;
  t.tag_id = prim.tag_id;
  const Intrinsics k(camera);
  const Vector3d o = t.c_M_o.translation();
  t.in_front = o.z() > 0.0;
  if (t.in_front) {
    t.center_px = k.toPixel(o.x() / o.z(), o.y() / o.z());
    t.in_image = camera.inImage(t.center_px);
  }
  auto proj = [&](const Vector3d& p_o, Eigen::Vector2d& uv) {
    const Vector3d p = t.c_M_o * p_o;
    if (p.z() <= 0.0) return false;
    uv = k.toPixel(p.x() / p.z(), p.y() / p.z());
    return true;
  };
  constexpr int kOutline = 120;
  auto fromOutline = [&]() {
    std::vector<cv::Point2f> pts;
    double area = 0.0;
    Eigen::Vector2d cen = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < t.outline_px.size(); ++i) {
      const Eigen::Vector2d& a = t.outline_px[i];
      const Eigen::Vector2d& b = t.outline_px[(i + 1) % t.outline_px.size()];
      const double cr = a.x() * b.y() - b.x() * a.y();
      area += cr;
      cen += cr * (a + b);
      pts.emplace_back(static_cast<float>(a.x()), static_cast<float>(a.y()));
    }
    if (std::abs(area) > 1e-12) t.outline_centroid_px = cen / (3.0 * area);
    cv::Point2f c;
    float rad = 0.0f;
    cv::minEnclosingCircle(pts, c, rad);
    t.enclosing_center_px = Eigen::Vector2d(static_cast<double>(c.x), static_cast<double>(c.y));
    t.enclosing_radius_px = static_cast<double>(rad);
    const cv::RotatedRect e = cv::fitEllipse(pts);
    t.semi_major_px = 0.5 * static_cast<double>(std::max(e.size.width, e.size.height));
    t.semi_minor_px = 0.5 * static_cast<double>(std::min(e.size.width, e.size.height));
  };
  switch (prim.shape) {
    case Shape::Sphere: {
      // Silhouette = image of the tangent circle of the cone from the camera centre.
      const double r = prim.size.x();
      const double D = o.norm();
      if (D <= r || !t.in_front) break;
      const Vector3d u = o / D;
      const Vector3d q = o * (1.0 - r * r / (D * D));
      const double rho = r * std::sqrt(1.0 - r * r / (D * D));
      Vector3d e1 = u.cross(Vector3d::UnitX());
      if (e1.norm() < 1e-6) e1 = u.cross(Vector3d::UnitY());
      e1.normalize();
      const Vector3d e2 = u.cross(e1);
      bool ok = true;
      for (int i = 0; i < kOutline && ok; ++i) {
        const double a = 2.0 * core::kPi * i / kOutline;
        const Vector3d p = q + rho * (std::cos(a) * e1 + std::sin(a) * e2);
        if (p.z() <= 0.0) ok = false;
        else t.outline_px.push_back(k.toPixel(p.x() / p.z(), p.y() / p.z()));
      }
      if (!ok) t.outline_px.clear();
      else fromOutline();
      break;
    }
    case Shape::Disc: {
      Eigen::Vector2d uv;
      for (int i = 0; i < kOutline; ++i) {
        const double a = 2.0 * core::kPi * i / kOutline;
        if (!proj(Vector3d(prim.size.x() * std::cos(a), prim.size.x() * std::sin(a), 0.0), uv)) {
          t.outline_px.clear();
          break;
        }
        t.outline_px.push_back(uv);
      }
      if (!t.outline_px.empty()) fromOutline();
      break;
    }
    case Shape::Rectangle: {
      const double a = prim.tag_id >= 0 ? 0.5 * prim.tag_size : 0.5 * prim.size.x();
      const double b = prim.tag_id >= 0 ? 0.5 * prim.tag_size : 0.5 * prim.size.y();
      Eigen::Vector2d uv;
      for (const auto& c : {Vector3d(-a, -b, 0), Vector3d(a, -b, 0), Vector3d(a, b, 0), Vector3d(-a, b, 0)}) {
        if (!proj(c, uv)) {
          t.corners_px.clear();
          break;
        }
        t.corners_px.push_back(uv);
      }
      break;
    }
    case Shape::Box: {
      const Vector3d hs = 0.5 * prim.size;
      Eigen::Vector2d uv;
      for (int i = 0; i < 8; ++i) {
        const Vector3d c((i & 1) ? hs.x() : -hs.x(), (i & 2) ? hs.y() : -hs.y(), (i & 4) ? hs.z() : -hs.z());
        if (!proj(c, uv)) {
          t.corners_px.clear();
          break;
        }
        t.corners_px.push_back(uv);
      }
      break;
    }
    case Shape::Cylinder:
    case Shape::Cone: break;
  }
  return t;
}

// ----------------------------------------------------------------------------------------------

SceneWorld::SceneWorld(Scene scene, Dynamic dynamic, Lighting lighting)
    : scene_(std::move(scene)), dynamic_(std::move(dynamic)), lighting_(lighting) {}

void SceneWorld::dynamicObjects(double t, std::vector<Primitive>& out) const {
  if (dynamic_) dynamic_(t, out);
}

struct Renderer::Impl {
  struct Rays {
    CameraKey key;
    RayGrid grid;
  };
  struct Layer {
    CameraKey key;
    cv::Mat bgr, depth;
    std::vector<ObjectTruth> truth;  // named static objects
  };
  std::list<Rays> rays;
  std::list<Layer> layers;

  const RayGrid& raysFor(const core::Camera& cam, std::size_t max_entries) {
    const CameraKey key = intrinsicsKey(cam);
    for (auto it = rays.begin(); it != rays.end(); ++it) {
      if (it->key == key) {
        rays.splice(rays.begin(), rays, it);
        return rays.front().grid;
      }
    }
    rays.push_front({key, makeRayGrid(cam)});
    while (rays.size() > max_entries) rays.pop_back();
    return rays.front().grid;
  }

  static void renderStatic(const Scene& scene, const Lighting& lighting, const core::Camera& cam,
                           const RayGrid& g, const RenderSettings& s, Layer& layer) {
    const Light light = lightFor(lighting, cam.c_M_w);
    const Intrinsics k(cam);
    std::vector<Prepared> prepared;
    prepared.reserve(scene.primitives.size());
    for (const auto& p : scene.primitives) prepared.push_back(prepare(p, cam.c_M_w));
    std::vector<const Prepared*> prims;
    for (auto& p : prepared) {
      p.bbox = projectedBox(p, k, g.w, g.h);
      if (p.bbox.area() > 0) prims.push_back(&p);
    }
    const cv::Rect full(0, 0, g.w, g.h);
    std::vector<double> acc(3 * static_cast<std::size_t>(g.w) * static_cast<std::size_t>(g.h), 0.0);
    layer.depth = cv::Mat(g.h, g.w, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
    layer.bgr = cv::Mat(g.h, g.w, CV_8UC3);
    Base base;
    base.background = scene.background_bgr;
    const bool thin = std::any_of(prims.begin(), prims.end(), [](const Prepared* p) { return p->thin; });
    // Thin static objects: supersample their boxes only.
    renderRegionParallel(full, prims, false, g, base, light, s, 1.0, acc.data(), &layer.depth);
    if (thin) {
      for (const Prepared* p : prims) {
        if (!p->thin) continue;
        std::vector<double> a2(3 * static_cast<std::size_t>(p->bbox.area()), 0.0);
        renderRegion(p->bbox, prims, true, g, base, light, s, 1.0, a2.data(), nullptr);
        for (int j = 0; j < p->bbox.height; ++j) {
          for (int i = 0; i < p->bbox.width; ++i) {
            const std::size_t src = 3 * (static_cast<std::size_t>(j) * static_cast<std::size_t>(p->bbox.width) + static_cast<std::size_t>(i));
            const std::size_t dst = 3 * (static_cast<std::size_t>(j + p->bbox.y) * static_cast<std::size_t>(g.w) + static_cast<std::size_t>(i + p->bbox.x));
            for (int c = 0; c < 3; ++c) acc[dst + static_cast<std::size_t>(c)] = a2[src + static_cast<std::size_t>(c)];
          }
        }
      }
    }
    accToImage(acc, full, layer.bgr);
    // Truth of the named static objects (visibility among static objects only).
    layer.truth.clear();
    std::vector<const Prepared*> named;
    for (const Prepared* p : prims) {
      if (p->named) named.push_back(p);
    }
    std::vector<int> footprint(prims.size(), 0), visible(prims.size(), 0);
    if (!named.empty()) countCoverage(full, prims, g, base, footprint, visible);
    for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
      const Primitive& p = scene.primitives[i];
      if (p.name.empty()) continue;
      ObjectTruth t = describe(p, cam);
      const auto it = std::find(prims.begin(), prims.end(), &prepared[i]);
      if (it != prims.end()) {
        const auto pi = static_cast<std::size_t>(it - prims.begin());
        t.footprint_px = footprint[pi];
        t.visible_fraction = footprint[pi] > 0 ? static_cast<double>(visible[pi]) / footprint[pi] : 0.0;
      } else {
        t.footprint_px = 0;
        t.visible_fraction = 0.0;
      }
      layer.truth.push_back(std::move(t));
    }
  }

  const Layer& layerFor(const World& world, const core::Camera& cam, const RenderSettings& s) {
    const Lighting lighting = world.lighting();
    const CameraKey key = fullKey(cam, &world, world.staticVersion(), lighting);
    for (auto it = layers.begin(); it != layers.end(); ++it) {
      if (it->key == key) {
        layers.splice(layers.begin(), layers, it);
        return layers.front();
      }
    }
    const auto max_entries = static_cast<std::size_t>(std::max(1, s.max_cached_cameras));
    const RayGrid& g = raysFor(cam, max_entries);
    Layer layer;
    layer.key = key;
    renderStatic(world.staticScene(), lighting, cam, g, s, layer);
    layers.push_front(std::move(layer));
    while (layers.size() > max_entries) layers.pop_back();
    return layers.front();
  }
};

Renderer::Renderer(const RenderSettings& settings) : settings_(settings), impl_(std::make_unique<Impl>()) {
  if (settings.supersampling < 1) throw InvalidInput("RenderSettings.supersampling must be >= 1");
  core::requireFinite(settings.edge_threshold, "RenderSettings.edge_threshold");
  if (settings.edge_threshold < 0.0) throw InvalidInput("RenderSettings.edge_threshold must be >= 0");
}
Renderer::~Renderer() = default;
Renderer::Renderer(Renderer&&) noexcept = default;
Renderer& Renderer::operator=(Renderer&&) noexcept = default;

cv::Mat Renderer::renderScene(const Scene& scene, const core::Camera& camera, const Lighting& lighting) {
  checkCamera(camera);
  const RayGrid& g = impl_->raysFor(camera, static_cast<std::size_t>(std::max(1, settings_.max_cached_cameras)));
  Impl::Layer layer;
  Impl::renderStatic(scene, lighting, camera, g, settings_, layer);
  return layer.bgr;
}

cv::Mat Renderer::render(const World& world, const core::Camera& camera, const ExposureSpec& exposure,
                         std::vector<ObjectTruth>* truth, const std::vector<Primitive>& extra) {
  checkCamera(camera);
  core::requireFinite(exposure.time, "ExposureSpec.time");
  core::requireFinite(exposure.duration, "ExposureSpec.duration");
  if (exposure.duration < 0.0) throw InvalidInput("ExposureSpec.duration must be >= 0");
  if (exposure.blur_samples < 1) throw InvalidInput("ExposureSpec.blur_samples must be >= 1");

  const Impl::Layer& layer = impl_->layerFor(world, camera, settings_);
  const RayGrid& g = impl_->raysFor(camera, static_cast<std::size_t>(std::max(1, settings_.max_cached_cameras)));
  const Light light = lightFor(world.lighting(), camera.c_M_w);
  const Intrinsics k(camera);
  cv::Mat image = layer.bgr.clone();
  Base base;
  base.bgr8 = &layer.bgr;
  base.depth = &layer.depth;

  const int n = exposure.duration > 0.0 ? exposure.blur_samples : 1;
  std::vector<std::vector<Primitive>> objects(static_cast<std::size_t>(n));
  std::vector<std::vector<Prepared>> prepared(static_cast<std::size_t>(n));
  std::vector<cv::Rect> boxes;
  for (int s = 0; s < n; ++s) {
    const double t = exposure.time + exposure.duration * ((s + 0.5) / n - 0.5);
    auto& objs = objects[static_cast<std::size_t>(s)];
    world.dynamicObjects(t, objs);
    objs.insert(objs.end(), extra.begin(), extra.end());
    auto& prep = prepared[static_cast<std::size_t>(s)];
    prep.reserve(objs.size());
    for (const auto& o : objs) {
      prep.push_back(prepare(o, camera.c_M_w));
      prep.back().bbox = projectedBox(prep.back(), k, g.w, g.h);
      boxes.push_back(prep.back().bbox);
    }
  }
  for (const cv::Rect& r : mergeRects(boxes)) {
    std::vector<double> acc(3 * static_cast<std::size_t>(r.area()), 0.0);
    for (int s = 0; s < n; ++s) {
      std::vector<const Prepared*> prims;
      bool thin = false;
      for (const auto& p : prepared[static_cast<std::size_t>(s)]) {
        if ((p.bbox & r).area() > 0) {
          prims.push_back(&p);
          thin = thin || p.thin;
        }
      }
      renderRegionParallel(r, prims, thin, g, base, light, settings_, 1.0 / n, acc.data(), nullptr);
    }
    accToImage(acc, r, image);
  }

  if (truth != nullptr) {
    *truth = layer.truth;
    // Moving objects at the capture time itself.
    std::vector<Primitive> now;
    world.dynamicObjects(exposure.time, now);
    now.insert(now.end(), extra.begin(), extra.end());
    std::vector<Prepared> prep;
    prep.reserve(now.size());
    for (const auto& o : now) {
      prep.push_back(prepare(o, camera.c_M_w));
      prep.back().bbox = projectedBox(prep.back(), k, g.w, g.h);
    }
    std::vector<const Prepared*> all;
    for (const auto& p : prep) all.push_back(&p);
    for (std::size_t i = 0; i < now.size(); ++i) {
      if (now[i].name.empty()) continue;
      ObjectTruth t = describe(now[i], camera);
      std::vector<int> footprint(all.size(), 0), visible(all.size(), 0);
      countCoverage(prep[i].bbox, all, g, base, footprint, visible);
      t.footprint_px = footprint[i];
      t.visible_fraction = footprint[i] > 0 ? static_cast<double>(visible[i]) / footprint[i] : 0.0;
      truth->push_back(std::move(t));
    }
  }
  return image;
}

}  // namespace viewline::sim
