#include "synthetic.h"

#include <algorithm>
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace viewline::vision::test {

namespace {

/// Calls f(u_sub, v_sub) -> optional colour contribution over a pixel box with ss x ss samples.
template <class F>
void supersample(cv::Mat& img, const cv::Rect& box, int ss, F&& f) {
  const cv::Rect roi = box & cv::Rect(0, 0, img.cols, img.rows);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      cv::Vec3d acc(0, 0, 0);
      int hits = 0;
      for (int sy = 0; sy < ss; ++sy)
        for (int sx = 0; sx < ss; ++sx) {
          const double u = x - 0.5 + (sx + 0.5) / ss, v = y - 0.5 + (sy + 0.5) / ss;
          cv::Vec3d c;
          if (f(u, v, c)) {
            acc += c;
            ++hits;
          }
        }
      if (hits == 0) continue;
      cv::Vec3b& px = img.at<cv::Vec3b>(y, x);
      const double w = static_cast<double>(hits) / (ss * ss);
      for (int k = 0; k < 3; ++k)
        px[k] = cv::saturate_cast<unsigned char>((1.0 - w) * px[k] + acc[k] / (ss * ss));
    }
  }
}

cv::Rect projectedBox(const core::Camera& cam, const std::vector<Eigen::Vector3d>& pts_w, int pad) {
  double u0 = 1e9, v0 = 1e9, u1 = -1e9, v1 = -1e9;
  for (const auto& p : pts_w) {
    const auto uv = cam.project(p);
    if (!uv) return {0, 0, static_cast<int>(cam.width), static_cast<int>(cam.height)};
    u0 = std::min(u0, uv->x());
    v0 = std::min(v0, uv->y());
    u1 = std::max(u1, uv->x());
    v1 = std::max(v1, uv->y());
  }
  const int x0 = static_cast<int>(std::floor(std::max(-1e6, u0))) - pad;
  const int y0 = static_cast<int>(std::floor(std::max(-1e6, v0))) - pad;
  const int x1 = static_cast<int>(std::ceil(std::min(1e6, u1))) + pad;
  const int y1 = static_cast<int>(std::ceil(std::min(1e6, v1))) + pad;
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

}  // namespace

cv::Mat texturedBackground(int width, int height, std::uint64_t seed, double mean, double amp) {
  core::Rng rng = core::makeRng(seed);
  cv::Mat small(height / 8 + 2, width / 8 + 2, CV_8UC3);
  for (int y = 0; y < small.rows; ++y)
    for (int x = 0; x < small.cols; ++x) {
      const double g = mean + core::uniform(rng, -amp, amp);
      small.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<unsigned char>(g * 0.85),
                                            cv::saturate_cast<unsigned char>(g * 0.95),
                                            cv::saturate_cast<unsigned char>(g));
    }
  cv::Mat out;
  cv::resize(small, out, cv::Size(width, height), 0, 0, cv::INTER_CUBIC);
  return out;
}

void renderSphere(cv::Mat& img, const core::Camera& cam, const Eigen::Vector3d& c_w, double r,
                  const cv::Vec3b& bgr, int ss, bool shaded) {
  const Eigen::Vector3d c_c = cam.toCamera(c_w);
  std::vector<Eigen::Vector3d> pts;
  for (int s = 0; s < 8; ++s) {
    const Eigen::Vector3d d((s & 1) ? r : -r, (s & 2) ? r : -r, (s & 4) ? r : -r);
    pts.push_back(c_w + 1.05 * d);
  }
  const Eigen::Vector3d light = Eigen::Vector3d(-0.4, -0.6, -0.7).normalized();  // camera frame, towards light
  supersample(img, projectedBox(cam, pts, 2), ss, [&](double u, double v, cv::Vec3d& col) {
    const Eigen::Vector2d xy = cam.pixelToNormalized({u, v});
    const Eigen::Vector3d ray = Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
    const double b = ray.dot(c_c);
    const double disc = b * b - (c_c.squaredNorm() - r * r);
    if (disc < 0.0) return false;
    const double t = b - std::sqrt(disc);
    const Eigen::Vector3d n = (t * ray - c_c) / r;
    double k = 1.0;
    if (shaded) k = 0.55 + 0.45 * std::max(0.0, n.dot(light));
    col = cv::Vec3d(bgr[0] * k, bgr[1] * k, bgr[2] * k);
    return true;
  });
}

void renderTable(cv::Mat& img, const core::Camera& cam, const Eigen::Isometry3d& w_M_t, double side,
                 double border, const cv::Vec3b& red, int ss) {
  const Eigen::Isometry3d c_M_t = cam.c_M_w * w_M_t;
  const Eigen::Isometry3d t_M_c = c_M_t.inverse();
  const double h = 0.5 * side, hb = h + border;
  std::vector<Eigen::Vector3d> pts;
  for (int s = 0; s < 4; ++s) pts.push_back(w_M_t * Eigen::Vector3d((s & 1) ? hb : -hb, (s & 2) ? hb : -hb, 0.0));
  const Eigen::Vector3d o_t = t_M_c.translation();
  supersample(img, projectedBox(cam, pts, 2), ss, [&](double u, double v, cv::Vec3d& col) {
    const Eigen::Vector2d xy = cam.pixelToNormalized({u, v});
    const Eigen::Vector3d d_t = t_M_c.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
    if (std::abs(d_t.z()) < 1e-12) return false;
    const double t = -o_t.z() / d_t.z();
    if (t <= 0.0) return false;
    const Eigen::Vector3d p = o_t + t * d_t;
    const double m = std::max(std::abs(p.x()), std::abs(p.y()));
    if (m > hb) return false;
    if (m <= h)
      col = cv::Vec3d(red[0], red[1], red[2]);
    else
      col = cv::Vec3d(20, 20, 20);
    return true;
  });
}

void renderTag36h11(cv::Mat& img, const core::Camera& cam, const Eigen::Isometry3d& w_M_tag, int id,
                    double size, int ss) {
  apriltag_family_t* tf = tag36h11_create();
  image_u8_t* im = apriltag_to_image(tf, id);
  const int n = static_cast<int>(im->width);  // 10: white quiet zone + 8 (black border + 6 data)
  const double cell = size / (n - 2);
  const double half = 0.5 * n * cell;
  const Eigen::Isometry3d tag_M_c = (cam.c_M_w * w_M_tag).inverse();
  std::vector<Eigen::Vector3d> pts;
  for (int s = 0; s < 4; ++s) pts.push_back(w_M_tag * Eigen::Vector3d((s & 1) ? half : -half, (s & 2) ? half : -half, 0.0));
  const Eigen::Vector3d o = tag_M_c.translation();
  supersample(img, projectedBox(cam, pts, 2), ss, [&](double u, double v, cv::Vec3d& col) {
    const Eigen::Vector2d xy = cam.pixelToNormalized({u, v});
    const Eigen::Vector3d d = tag_M_c.linear() * Eigen::Vector3d(xy.x(), xy.y(), 1.0);
    if (std::abs(d.z()) < 1e-12) return false;
    const double t = -o.z() / d.z();
    if (t <= 0.0) return false;
    const Eigen::Vector3d p = o + t * d;
    const int cx = static_cast<int>(std::floor((p.x() + half) / cell));
    const int cy = static_cast<int>(std::floor((half - p.y()) / cell));  // rows run along -y
    if (cx < 0 || cy < 0 || cx >= n || cy >= n) return false;
    const double g = im->buf[cy * static_cast<int>(im->stride) + cx] > 127 ? 235.0 : 15.0;
    col = cv::Vec3d(g, g, g);
    return true;
  });
  image_u8_destroy(im);
  tag36h11_destroy(tf);
}

cv::Mat screenWithDisc(int width, int height, double u, double v, double R, int bright, int dark, int ss) {
  cv::Mat img(height, width, CV_8UC3, cv::Scalar(bright, bright, bright));
  const cv::Rect box(static_cast<int>(u - R) - 2, static_cast<int>(v - R) - 2, static_cast<int>(2 * R) + 5,
                     static_cast<int>(2 * R) + 5);
  supersample(img, box, ss, [&](double x, double y, cv::Vec3d& col) {
    if ((x - u) * (x - u) + (y - v) * (y - v) > R * R) return false;
    col = cv::Vec3d(dark, dark, dark);
    return true;
  });
  cv::Mat gray;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  return gray;
}

void addNoise(cv::Mat& img, double sigma, core::Rng& rng) {
  std::normal_distribution<double> n(0.0, sigma);
  const int ch = img.channels();
  for (int y = 0; y < img.rows; ++y) {
    unsigned char* p = img.ptr<unsigned char>(y);
    for (int x = 0; x < img.cols * ch; ++x) p[x] = cv::saturate_cast<unsigned char>(p[x] + n(rng));
  }
}

}  // namespace viewline::vision::test
