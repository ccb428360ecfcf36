#include "viewline/calib/board.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <set>
#include <sstream>
#include <visp3/core/vpImageConvert.h>
#include <visp3/detection/vpDetectorAprilTag.h>

#include "viewline/core/error.h"

namespace viewline::calib {
namespace {

vpDetectorAprilTag::vpAprilTagFamily familyOf(const std::string& f) {
  if (f == "36h11") return vpDetectorAprilTag::TAG_36h11;
  if (f == "25h9") return vpDetectorAprilTag::TAG_25h9;
  if (f == "16h5") return vpDetectorAprilTag::TAG_16h5;
  if (f == "circle21h7") return vpDetectorAprilTag::TAG_CIRCLE21h7;
  throw core::InvalidInput("tag_family '" + f + "': expected one of 36h11, 25h9, 16h5, circle21h7");
}

const std::vector<std::pair<std::string, BoardType>>& typeNames() {
  static const std::vector<std::pair<std::string, BoardType>> names = {
      {"chessboard", BoardType::Chessboard},
      {"circles_grid", BoardType::CirclesGrid},
      {"asymmetric_circles_grid", BoardType::AsymmetricCirclesGrid},
      {"apriltag_grid", BoardType::AprilTagGrid},
      {"apriltag", BoardType::AprilTag},
      {"charuco", BoardType::ChArUco}};
  return names;
}

const std::vector<std::pair<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME>>& dictionaryNames() {
  using namespace cv::aruco;
  static const std::vector<std::pair<std::string, PREDEFINED_DICTIONARY_NAME>> names = {
      {"DICT_4X4_50", DICT_4X4_50},     {"DICT_4X4_100", DICT_4X4_100},     {"DICT_4X4_250", DICT_4X4_250},
      {"DICT_4X4_1000", DICT_4X4_1000}, {"DICT_5X5_50", DICT_5X5_50},       {"DICT_5X5_100", DICT_5X5_100},
      {"DICT_5X5_250", DICT_5X5_250},   {"DICT_5X5_1000", DICT_5X5_1000},   {"DICT_6X6_50", DICT_6X6_50},
      {"DICT_6X6_100", DICT_6X6_100},   {"DICT_6X6_250", DICT_6X6_250},     {"DICT_6X6_1000", DICT_6X6_1000},
      {"DICT_7X7_50", DICT_7X7_50},     {"DICT_7X7_100", DICT_7X7_100},     {"DICT_7X7_250", DICT_7X7_250},
      {"DICT_7X7_1000", DICT_7X7_1000}, {"DICT_ARUCO_ORIGINAL", DICT_ARUCO_ORIGINAL}};
  return names;
}

std::vector<std::string> dictionaryChoices() {
  std::vector<std::string> out;
  for (const auto& d : dictionaryNames()) out.push_back(d.first);
  return out;
}

bool isTagBoard(BoardType t) { return t == BoardType::AprilTagGrid || t == BoardType::AprilTag; }

}  // namespace

cv::Ptr<cv::aruco::Dictionary> arucoDictionary(const std::string& name) {
  for (const auto& d : dictionaryNames())
    if (d.first == name) return cv::aruco::getPredefinedDictionary(d.second);
  std::string list;
  for (const auto& c : dictionaryChoices()) list += (list.empty() ? "" : ", ") + c;
  throw core::InvalidInput("dictionary '" + name + "': expected one of " + list);
}

cv::Ptr<cv::aruco::CharucoBoard> charucoBoard(const BoardSpec& board) {
  if (board.type != BoardType::ChArUco) throw core::InvalidInput("charucoBoard: board is " + toString(board.type));
  board.validate();
  return cv::aruco::CharucoBoard::create(board.cols, board.rows, static_cast<float>(board.spacing),
                                         static_cast<float>(board.marker_size), arucoDictionary(board.dictionary));
}

std::string toString(BoardType t) {
  for (const auto& n : typeNames())
    if (n.second == t) return n.first;
  return "?";
}

std::string BoardSpec::describe() const {
  std::ostringstream os;
  os << toString(type);
  if (type == BoardType::ChArUco)
    os << " " << cols << "x" << rows << " squares of " << spacing << " m, markers " << dictionary << " of "
       << marker_size << " m";
  else if (type != BoardType::AprilTag)
    os << " " << cols << "x" << rows << ", spacing " << spacing << " m";
  if (isTagBoard(type)) os << ", tags " << tag_family << " of " << tag_size << " m";
  return os.str();
}

void BoardSpec::validate(const std::string& where) const {
  if (type != BoardType::AprilTag) {
    if (cols < 2 || rows < 2 || cols > 100 || rows > 100)
      throw core::InvalidInput(where + ": cols and rows must be in 2..100, got " + std::to_string(cols) + "x" +
                               std::to_string(rows));
    if (!(spacing > 0.0) || spacing > 10.0)
      throw core::InvalidInput(where + ": spacing must be a positive length in metres");
  }
  if (isTagBoard(type)) {
    familyOf(tag_family);
    if (!(tag_size > 0.0) || tag_size > 10.0)
      throw core::InvalidInput(where + ": tag_size must be a positive length in metres");
    if (type == BoardType::AprilTagGrid && tag_size >= spacing)
      throw core::InvalidInput(where + ": tag_size must be smaller than spacing (the tag centre distance)");
  }
  if (type == BoardType::ChArUco) {
    if (cols < 3 || rows < 3)
      throw core::InvalidInput(where + ": charuco cols and rows (squares) must be at least 3, got " +
                               std::to_string(cols) + "x" + std::to_string(rows));
    if (!(marker_size > 0.0) || !(marker_size < spacing))
      throw core::InvalidInput(where + ": marker_size must be a positive length in metres smaller than spacing (the square edge)");
    try {
      const int markers = cols * rows / 2;
      const int available = arucoDictionary(dictionary)->bytesList.rows;
      if (markers > available)
        throw core::InvalidInput("dictionary '" + dictionary + "' has " + std::to_string(available) +
                                 " markers, the board needs " + std::to_string(markers));
    } catch (const core::InvalidInput& e) {
      throw core::InvalidInput(where + ": " + e.what());
    }
  }
}

std::vector<cv::Point3f> tagCorners3d(double size) {
  // ViSP (vpDetectorAprilTag::getTagsPoints3D): corners 0..3 at (-s/2,-s/2), (s/2,-s/2), (s/2,s/2), (-s/2,s/2)
  // in the tag frame: x right and y up on the printed tag, z out of it (towards the viewer).
  const float h = static_cast<float>(size / 2.0);
  return {{-h, -h, 0.f}, {h, -h, 0.f}, {h, h, 0.f}, {-h, h, 0.f}};
}

std::vector<cv::Point3f> BoardSpec::objectPoints() const {
  std::vector<cv::Point3f> pts;
  const float s = static_cast<float>(spacing);
  // charuco: the inner corners, ids row-major as OpenCV numbers them.
  const int nc = type == BoardType::ChArUco ? cols - 1 : cols, nr = type == BoardType::ChArUco ? rows - 1 : rows;
  for (int r = 0; r < nr; ++r)
    for (int c = 0; c < nc; ++c) {
      if (type == BoardType::AsymmetricCirclesGrid)
        pts.emplace_back(static_cast<float>(2 * c + r % 2) * s, static_cast<float>(r) * s, 0.f);
      else if (type == BoardType::AprilTagGrid)
        for (const auto& p : tagCorners3d(tag_size))
          pts.emplace_back(static_cast<float>(c) * s + p.x, static_cast<float>(r) * s - p.y, 0.f);
      else
        pts.emplace_back(static_cast<float>(c) * s, static_cast<float>(r) * s, 0.f);
    }
  return pts;
}

BoardSpec readBoard(const io::ConfigNode& n) {
  BoardSpec b;
  std::vector<std::string> choices;
  for (const auto& t : typeNames()) choices.push_back(t.first);
  const std::string type = n.getChoice("type", choices);
  for (const auto& t : typeNames())
    if (t.first == type) b.type = t.second;
  if (b.type != BoardType::AprilTag) {
    b.cols = n.get<int>("cols");
    b.rows = n.get<int>("rows");
    b.spacing = n.get<double>("spacing");
  }
  if (isTagBoard(b.type)) {
    b.tag_family = n.getChoiceOr("tag_family", {"36h11", "25h9", "16h5", "circle21h7"}, "36h11");
    b.tag_size = n.get<double>("tag_size");
  }
  if (b.type == BoardType::AprilTagGrid) b.first_id = n.getOr<int>("first_id", 0);
  if (b.type == BoardType::AprilTag) b.tag_ids = n.getOr<std::vector<int>>("tag_ids", {});
  if (b.type == BoardType::ChArUco) {
    b.marker_size = n.get<double>("marker_size");
    b.dictionary = n.getChoice("dictionary", dictionaryChoices());
  }
  try {
    b.validate(n.location() + ": board");
  } catch (const core::InvalidInput&) {
    throw;
  }
  return b;
}

BoardSpec loadBoard(const std::string& path) {
  const auto cfg = io::ConfigNode::loadFile(path);
  BoardSpec b = readBoard(cfg);
  cfg.finish();
  return b;
}

cv::Mat readGray(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) throw core::InvalidInput(path + ": image file does not exist");
  cv::Mat img = cv::imread(path, cv::IMREAD_GRAYSCALE);
  if (img.empty()) throw core::InvalidInput(path + ": cannot decode the image (unreadable or not an image)");
  return img;
}

std::map<int, std::vector<cv::Point2f>> detectAprilTags(const cv::Mat& gray, const std::string& family) {
  vpImage<unsigned char> I;
  vpImageConvert::convert(gray, I);
  vpDetectorAprilTag detector(familyOf(family));
  detector.setAprilTagQuadDecimate(1.0);
  std::map<int, std::vector<cv::Point2f>> out;
  if (!detector.detect(I)) return out;
  const auto ids = detector.getTagsId();
  const auto corners = detector.getTagsCorners();
  for (std::size_t i = 0; i < ids.size(); ++i) {
    std::vector<cv::Point2f> c;
    for (const auto& ip : corners[i]) c.emplace_back(static_cast<float>(ip.get_u()), static_cast<float>(ip.get_v()));
    out[ids[i]] = c;
  }
  return out;
}

Detection detectBoard(const cv::Mat& gray, const BoardSpec& board) {
  Detection d;
  if (gray.empty() || gray.type() != CV_8UC1) {
    d.reason = "not an 8-bit grey image";
    return d;
  }
  BoardObservation obs;
  const cv::Size pattern(board.cols, board.rows);
  switch (board.type) {
    case BoardType::Chessboard: {
      std::vector<cv::Point2f> corners;
      const int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
      if (!cv::findChessboardCorners(gray, pattern, corners, flags)) {
        d.reason = "chessboard " + std::to_string(board.cols) + "x" + std::to_string(board.rows) +
                   " inner corners not found";
        return d;
      }
      // Search window: at most ~40% of the smallest corner spacing, so that it never reaches the
      // neighbouring corners on small or distant boards.
      double min_d = 1e9;
      for (int r = 0; r < board.rows; ++r)
        for (int c = 0; c + 1 < board.cols; ++c)
          min_d = std::min(min_d, cv::norm(corners[static_cast<std::size_t>(r * board.cols + c + 1)] -
                                           corners[static_cast<std::size_t>(r * board.cols + c)]));
      for (int r = 0; r + 1 < board.rows; ++r)
        for (int c = 0; c < board.cols; ++c)
          min_d = std::min(min_d, cv::norm(corners[static_cast<std::size_t>((r + 1) * board.cols + c)] -
                                           corners[static_cast<std::size_t>(r * board.cols + c)]));
      const int win = std::clamp(static_cast<int>(0.4 * min_d), 2, 11);
      cv::cornerSubPix(gray, corners, cv::Size(win, win), cv::Size(-1, -1),
                       cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
      obs.image_points = corners;
      obs.object_points = board.objectPoints();
      break;
    }
    case BoardType::CirclesGrid:
    case BoardType::AsymmetricCirclesGrid: {
      std::vector<cv::Point2f> centres;
      const int flags = board.type == BoardType::CirclesGrid ? cv::CALIB_CB_SYMMETRIC_GRID : cv::CALIB_CB_ASYMMETRIC_GRID;
      bool found = cv::findCirclesGrid(gray, pattern, centres, flags);
      if (!found) {  // dark circles on a light background are the default; try the inverse
        cv::Mat inv = 255 - gray;
        found = cv::findCirclesGrid(inv, pattern, centres, flags);
      }
      if (!found) {
        d.reason = toString(board.type) + " " + std::to_string(board.cols) + "x" + std::to_string(board.rows) +
                   " not found";
        return d;
      }
      obs.image_points = centres;
      obs.object_points = board.objectPoints();
      break;
    }
    case BoardType::AprilTagGrid:
    case BoardType::AprilTag: {
      const auto tags = detectAprilTags(gray, board.tag_family);
      const int n_grid = board.cols * board.rows;
      for (const auto& [id, corners] : tags) {
        if (board.type == BoardType::AprilTagGrid) {
          const int k = id - board.first_id;
          if (k < 0 || k >= n_grid) continue;
          const float cx = static_cast<float>((k % board.cols) * board.spacing);
          const float cy = static_cast<float>((k / board.cols) * board.spacing);
          const auto c3 = tagCorners3d(board.tag_size);
          for (int j = 0; j < 4; ++j) {
            obs.image_points.push_back(corners[static_cast<std::size_t>(j)]);
            // ViSP's tag frame has y up the printed tag (z out of it); the board's y runs down.
            obs.object_points.emplace_back(cx + c3[static_cast<std::size_t>(j)].x,
                                           cy - c3[static_cast<std::size_t>(j)].y, 0.f);
          }
        } else {
          if (!board.tag_ids.empty() && std::find(board.tag_ids.begin(), board.tag_ids.end(), id) == board.tag_ids.end())
            continue;
          const auto c3 = tagCorners3d(board.tag_size);
          obs.image_points.insert(obs.image_points.end(), corners.begin(), corners.end());
          obs.object_points.insert(obs.object_points.end(), c3.begin(), c3.end());
        }
        obs.tag_ids.push_back(id);
      }
      const std::size_t need = board.type == BoardType::AprilTagGrid ? 2 : 1;
      if (obs.tag_ids.size() < need) {
        d.reason = "found " + std::to_string(obs.tag_ids.size()) + " usable " + board.tag_family +
                   " tags, need at least " + std::to_string(need);
        return d;
      }
      break;
    }
    case BoardType::ChArUco: {
      const auto cb = charucoBoard(board);
      std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
      std::vector<int> marker_ids;
      cv::aruco::detectMarkers(gray, cb->dictionary, marker_corners, marker_ids,
                               cv::aruco::DetectorParameters::create(), rejected);
      std::vector<cv::Point2f> corners;
      std::vector<int> ids;
      if (!marker_ids.empty())
        cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, cb, corners, ids);
      const std::size_t need = 6;
      const std::string what = "charuco " + std::to_string(board.cols) + "x" + std::to_string(board.rows) + " (" +
                               board.dictionary + "): ";
      if (ids.size() < need) {
        d.reason = what + "found " + std::to_string(ids.size()) + " corners from " + std::to_string(marker_ids.size()) +
                   " markers, need at least " + std::to_string(need);
        return d;
      }
      // Corners all on one row or column of the board give no homography (degenerate for calibration).
      const int nc = board.cols - 1;
      bool one_row = true, one_col = true;
      for (const int id : ids) {
        one_row = one_row && id / nc == ids.front() / nc;
        one_col = one_col && id % nc == ids.front() % nc;
      }
      if (one_row || one_col) {
        d.reason = what + "the " + std::to_string(ids.size()) + " corners found lie on one line of the board";
        return d;
      }
      // OpenCV 4.6's interpolateCornersCharuco returns corners about half a pixel off (+0.5, +0.5)
      // from cornerSubPix's pixel-centre convention, which findChessboardCorners and the renderers
      // use (measured on a drawn board: 100.0 where cornerSubPix gives 99.5; a known bug,
      // opencv/opencv#25539, fixed upstream after 4.6). Refine each corner
      // again, its search window kept inside the white gap between the corner and the markers
      // around it (the gap is ~0.7 of the distance to the nearest marker corner), less 2 px of blur.
      for (std::size_t i = 0; i < corners.size(); ++i) {
        double near = 1e9;
        for (const auto& m : marker_corners)
          for (const auto& p : m) near = std::min(near, cv::norm(p - corners[i]));
        const int win = std::clamp(static_cast<int>(0.7 * near - 2.0), 2, 10);
        std::vector<cv::Point2f> one{corners[i]};
        cv::cornerSubPix(gray, one, cv::Size(win, win), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
        corners[i] = one.front();
      }
      const auto all = board.objectPoints();
      for (std::size_t i = 0; i < ids.size(); ++i) {
        obs.image_points.push_back(corners[i]);
        obs.object_points.push_back(all[static_cast<std::size_t>(ids[i])]);
        obs.corner_ids.push_back(ids[i]);
      }
      break;
    }
  }
  d.observation = std::move(obs);
  return d;
}

}  // namespace viewline::calib
