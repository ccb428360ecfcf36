#include "viewline/calib/intrinsics.h"

#include <cmath>
#include <iomanip>
#include <opencv2/calib3d.hpp>
#include <sstream>
#include <visp3/core/vpMeterPixelConversion.h>
#include <visp3/vision/vpCalibration.h>

#include "viewline/core/error.h"
#include "viewline/io/files.h"

namespace viewline::calib {
namespace {

vpHomogeneousMatrix fromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  vpHomogeneousMatrix M;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) M[static_cast<unsigned>(r)][static_cast<unsigned>(c)] = R.at<double>(r, c);
    M[static_cast<unsigned>(r)][3] = tvec.at<double>(r);
  }
  return M;
}

struct CvFit {
  cv::Mat K, D, std_dev, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  double rms = 0.0;
};

CvFit fitOpenCv(const std::vector<ViewInput>& views, cv::Size size, const IntrinsicsOptions& opt) {
  std::vector<std::vector<cv::Point3f>> obj;
  std::vector<std::vector<cv::Point2f>> img;
  for (const auto& v : views) {
    obj.push_back(v.observation.object_points);
    img.push_back(v.observation.image_points);
  }
  CvFit f;
  cv::Mat std_extr;
  int flags = opt.fix_k3 ? cv::CALIB_FIX_K3 : 0;
  // Non-planar-free boards (all ours are planar) need an initial guess only for partial views.
  f.rms = cv::calibrateCamera(obj, img, size, f.K, f.D, f.rvecs, f.tvecs, f.std_dev, std_extr, f.per_view, flags,
                              cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-12));
  return f;
}

}  // namespace

double vispReprojectionRms(const vpCameraParameters& cam, const std::vector<vpHomogeneousMatrix>& c_M_o,
                           const std::vector<BoardObservation>& views) {
  double sum = 0.0;
  std::size_t n = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const auto& o = views[v];
    for (std::size_t i = 0; i < o.object_points.size(); ++i) {
      const vpColVector p = c_M_o[v] * vpColVector({o.object_points[i].x, o.object_points[i].y,
                                                      o.object_points[i].z, 1.0});
      double u = 0, w = 0;
      vpMeterPixelConversion::convertPoint(cam, p[0] / p[2], p[1] / p[2], u, w);
      sum += std::pow(u - static_cast<double>(o.image_points[i].x), 2) + std::pow(w - static_cast<double>(o.image_points[i].y), 2);
      ++n;
    }
  }
  return n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
}

IntrinsicsResult calibrateIntrinsics(const std::vector<ViewInput>& views_in, cv::Size size,
                                     const IntrinsicsOptions& opt) {
  if (size.width <= 0 || size.height <= 0) throw core::InvalidInput("calibrateIntrinsics: image size is empty");
  IntrinsicsResult r;
  r.image_size = size;
  std::vector<ViewInput> views;
  for (const auto& v : views_in) {
    if (v.observation.image_points.size() < 4 || v.observation.image_points.size() != v.observation.object_points.size())
      r.rejected.push_back({v.name, "fewer than 4 matched points"});
    else
      views.push_back(v);
  }
  auto tooFew = [&](const std::string& stage) {
    std::ostringstream os;
    os << "too few usable views" << stage << ": " << views.size() << ", need at least " << opt.min_views;
    for (const auto& rej : r.rejected) os << "\n  rejected " << rej.name << ": " << rej.reason;
    return core::InvalidInput(os.str());
  };
  if (static_cast<int>(views.size()) < opt.min_views) throw tooFew("");

  CvFit f = fitOpenCv(views, size, opt);
  // Reject views whose own error is far off (a mis-detected board), then refit once.
  std::vector<ViewInput> kept;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const double e = f.per_view.at<double>(static_cast<int>(i));
    if (e > opt.max_view_rms_px) {
      std::ostringstream os;
      os << std::fixed << std::setprecision(2) << "reprojection error " << e << " px > " << opt.max_view_rms_px
         << " px after the first fit";
      r.rejected.push_back({views[i].name, os.str()});
    } else {
      kept.push_back(views[i]);
    }
  }
  if (kept.size() != views.size()) {
    views = kept;
    if (static_cast<int>(views.size()) < opt.min_views) throw tooFew(" after rejecting outlier views");
    f = fitOpenCv(views, size, opt);
  }
  if (!cv::checkRange(f.K) || !cv::checkRange(f.D) || !(f.K.at<double>(0, 0) > 0.0))
    throw core::NumericalError("calibrateIntrinsics: OpenCV calibration diverged (non-finite parameters)");

  r.rms_px = f.rms;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r.opencv.camera_matrix(i, j) = f.K.at<double>(i, j);
  r.opencv.distortion.resize(static_cast<Eigen::Index>(f.D.total()));
  for (int i = 0; i < static_cast<int>(f.D.total()); ++i) r.opencv.distortion(i) = f.D.at<double>(i);
  r.opencv.width = static_cast<unsigned>(size.width);
  r.opencv.height = static_cast<unsigned>(size.height);
  r.opencv.rms_px = f.rms;
  r.std_dev.resize(static_cast<Eigen::Index>(f.std_dev.total()));
  for (int i = 0; i < static_cast<int>(f.std_dev.total()); ++i) r.std_dev(i) = f.std_dev.at<double>(i);
  r.rvecs = f.rvecs;
  r.tvecs = f.tvecs;
  for (std::size_t i = 0; i < views.size(); ++i) {
    r.view_names.push_back(views[i].name);
    r.view_rms_px.push_back(f.per_view.at<double>(static_cast<int>(i)));
  }

  if (opt.fit_visp) {
    std::vector<vpCalibration> table;
    std::vector<BoardObservation> obs;
    for (std::size_t i = 0; i < views.size(); ++i) {
      vpCalibration c;
      c.clearPoint();
      const auto& o = views[i].observation;
      for (std::size_t k = 0; k < o.image_points.size(); ++k) {
        vpImagePoint ip(o.image_points[k].y, o.image_points[k].x);
        c.addPoint(o.object_points[k].x, o.object_points[k].y, o.object_points[k].z, ip);
      }
      c.cMo = fromRvecTvec(f.rvecs[i], f.tvecs[i]);
      c.cMo_dist = c.cMo;
      table.push_back(c);
      obs.push_back(o);
    }
    const double fx = f.K.at<double>(0, 0), fy = f.K.at<double>(1, 1);
    const double cx = f.K.at<double>(0, 2), cy = f.K.at<double>(1, 2);
    double err = 0.0;
    // Full Gauss-Newton steps: started from OpenCV's solution the VVS converges in a few tens of
    // iterations instead of thousands with ViSP's default gain (0.25).
    const double gain = vpCalibration::getLambda();
    vpCalibration::setLambda(1.0);
    struct RestoreGain {
      double g;
      ~RestoreGain() { vpCalibration::setLambda(g); }
    } restore{gain};
    vpCameraParameters cam;
    cam.initPersProjWithoutDistortion(fx, fy, cx, cy);
    if (vpCalibration::computeCalibrationMulti(vpCalibration::CALIB_VIRTUAL_VS, table, cam, err, false) != 0)
      throw core::NumericalError("vpCalibration failed on the model without distortion");
    r.visp_without = cam;
    std::vector<vpHomogeneousMatrix> poses;
    for (const auto& c : table) poses.push_back(c.cMo);
    r.visp_without_rms_px = vispReprojectionRms(cam, poses, obs);

    vpCameraParameters camd;
    camd.initPersProjWithDistortion(fx, fy, cx, cy, 0.0, 0.0);
    if (vpCalibration::computeCalibrationMulti(vpCalibration::CALIB_VIRTUAL_VS_DIST, table, camd, err, false) != 0)
      throw core::NumericalError("vpCalibration failed on the model with distortion");
    r.visp_with = camd;
    r.visp_c_M_o.clear();
    for (const auto& c : table) r.visp_c_M_o.push_back(c.cMo_dist);
    r.visp_with_rms_px = vispReprojectionRms(camd, r.visp_c_M_o, obs);
  }
  return r;
}

IntrinsicsResult calibrateFromImages(const std::vector<std::string>& files, const BoardSpec& board,
                                     const IntrinsicsOptions& opt) {
  if (board.type == BoardType::AprilTag)
    throw core::InvalidInput("board type apriltag (independent tags) cannot calibrate intrinsics: use apriltag_grid");
  if (files.empty()) throw core::InvalidInput("no images given");
  std::vector<ViewInput> views;
  std::vector<RejectedView> rejected;
  cv::Size size;
  std::string first;
  for (const auto& file : files) {
    const cv::Mat gray = readGray(file);  // unreadable: an error, not a rejection
    if (size.area() == 0) {
      size = gray.size();
      first = file;
    } else if (gray.size() != size) {
      throw core::InvalidInput(file + ": image size " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows) +
                               " differs from " + std::to_string(size.width) + "x" + std::to_string(size.height) +
                               " of " + first + " (all images of one camera must have the same size)");
    }
    Detection d = detectBoard(gray, board);
    if (d.observation)
      views.push_back({file, std::move(*d.observation)});
    else
      rejected.push_back({file, d.reason});
  }
  std::vector<ViewInput> all = views;
  IntrinsicsResult r;
  try {
    r = calibrateIntrinsics(all, size, opt);
  } catch (const core::InvalidInput& e) {
    std::string msg = e.what();
    for (const auto& rej : rejected) msg += "\n  rejected " + rej.name + ": " + rej.reason;
    throw core::InvalidInput(msg);
  }
  r.rejected.insert(r.rejected.begin(), rejected.begin(), rejected.end());
  return r;
}

std::string IntrinsicsResult::report() const {
  std::ostringstream os;
  os << std::fixed << std::setprecision(3);
  const auto& K = opencv.camera_matrix;
  os << "image size: " << image_size.width << "x" << image_size.height << ", views used: " << view_names.size()
     << ", rejected: " << rejected.size() << "\n";
  for (const auto& rej : rejected) os << "  rejected " << rej.name << ": " << rej.reason << "\n";
  os << "OpenCV model (k1 k2 p1 p2 k3): RMS reprojection error " << rms_px << " px\n";
  auto sd = [&](Eigen::Index i) { return i < std_dev.size() ? std_dev(i) : 0.0; };
  os << "  fx = " << K(0, 0) << " +- " << sd(0) << "   fy = " << K(1, 1) << " +- " << sd(1) << "\n";
  os << "  cx = " << K(0, 2) << " +- " << sd(2) << "   cy = " << K(1, 2) << " +- " << sd(3) << "\n";
  os << std::setprecision(5) << "  dist =";
  for (Eigen::Index i = 0; i < opencv.distortion.size(); ++i) os << " " << opencv.distortion(i) << " (+-" << sd(4 + i) << ")";
  os << "\n" << std::setprecision(3);
  if (visp_without_rms_px >= 0.0) {
    os << "ViSP model without distortion: px = " << visp_without.get_px() << " py = " << visp_without.get_py()
       << " u0 = " << visp_without.get_u0() << " v0 = " << visp_without.get_v0() << ", RMS " << visp_without_rms_px
       << " px\n";
    os << "ViSP model with distortion:    px = " << visp_with.get_px() << " py = " << visp_with.get_py()
       << " u0 = " << visp_with.get_u0() << " v0 = " << visp_with.get_v0() << std::setprecision(5)
       << " kud = " << visp_with.get_kud() << " kdu = " << visp_with.get_kdu() << std::setprecision(3) << ", RMS "
       << visp_with_rms_px << " px\n";
  }
  os << "per-view RMS (px):\n";
  for (std::size_t i = 0; i < view_names.size(); ++i) os << "  " << view_names[i] << ": " << view_rms_px[i] << "\n";
  return os.str();
}

void saveIntrinsics(const IntrinsicsResult& r, const std::string& camera_name, const std::string& visp_xml,
                    const std::string& opencv_yaml) {
  io::StagedFiles out;
  if (!visp_xml.empty()) {
    std::ostringstream info;
    info << std::setprecision(6) << "<reprojection_error_px_without_distortion>" << r.visp_without_rms_px
         << "</reprojection_error_px_without_distortion><reprojection_error_px_with_distortion>" << r.visp_with_rms_px
         << "</reprojection_error_px_with_distortion><views>" << r.view_names.size() << "</views>";
    const std::string tmp = out.stage(visp_xml) + ".xml";
    io::writeVispCameraXmlTo(tmp, camera_name, r.visp_without, r.visp_with,
                             static_cast<unsigned>(r.image_size.width), static_cast<unsigned>(r.image_size.height),
                             info.str());
    std::rename(tmp.c_str(), tmp.substr(0, tmp.size() - 4).c_str());
  }
  if (!opencv_yaml.empty()) io::writeOpenCvIntrinsicsTo(out.stage(opencv_yaml), r.opencv, opencv_yaml);
  out.commit();
}

}  // namespace viewline::calib
