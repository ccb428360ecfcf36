#pragma once
// Calibration targets and their detection in images.
//
// Board files (YAML, strict keys, read with io::ConfigNode):
//   type: chessboard          # chessboard | circles_grid | asymmetric_circles_grid | apriltag_grid | apriltag | charuco
//   cols: 9                   # inner corners (chessboard), circles per row, or squares per row (charuco)
//   rows: 6                   # inner corners, circles per column, or squares per column (charuco)
//   spacing: 0.025            # metres between neighbouring corners / circle centres / tag centres
//                             # (charuco: the square edge)
//   tag_family: 36h11         # AprilTag family (apriltag*, default 36h11)
//   tag_size: 0.053           # metres, black border edge (apriltag*)
//   first_id: 0               # id of the top-left tag of an apriltag_grid (row-major)
//   tag_ids: [0, 3]           # apriltag: only these tags (default: all)
//   marker_size: 0.019        # charuco: metres, black border edge of the ArUco markers (< spacing)
//   dictionary: DICT_5X5_100  # charuco: OpenCV ArUco dictionary (DICT_4X4_50 .. DICT_7X7_1000,
//                             # DICT_ARUCO_ORIGINAL); it must hold cols * rows / 2 markers
//
// A charuco board (OpenCV 4.6 layout: top-left square black, markers 0, 1, ... in the white squares
// row by row) is a chessboard of cols x rows squares whose (cols - 1) x (rows - 1) inner corners
// are identified by the markers around them, so a partly hidden board still gives the corners it
// shows; its frame is the chessboard's (origin at the top-left inner corner).
// Board frame: origin at the first corner / circle / top-left tag centre, x along a row, y down
// the columns, z into the board (away from a camera that sees it), as OpenCV and ViSP do.
// `apriltag` is not a rigid board: each detected tag gets its own pose in ViSP's tag frame (origin
// at the tag centre, x right and y up on the printed tag, z out of it, towards the viewer), used by
// compute-board-poses and to anchor a world frame.

#include <map>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "viewline/io/config.h"

namespace viewline::calib {

/// Kind of calibration target (the `type:` key of a board file).
enum class BoardType { Chessboard, CirclesGrid, AsymmetricCirclesGrid, AprilTagGrid, AprilTag, ChArUco };

/// A calibration target as a board file describes it (metres; board frame x along a row, y down the columns,
/// z into the board).
struct BoardSpec {
  BoardType type = BoardType::Chessboard;  ///< target kind
  int cols = 9;  ///< inner corners (chessboard), circles per row, or squares per row (charuco)
  int rows = 6;  ///< inner corners, circles per column, or squares per column (charuco)
  double spacing = 0.025;  ///< m between neighbouring corners / circle centres / tag centres (charuco: square edge)
  std::string tag_family = "36h11";  ///< AprilTag family (apriltag*), e.g. "36h11"
  double tag_size = 0.0;  ///< m, black border edge of a tag (apriltag*)
  int first_id = 0;  ///< id of the top-left tag of an apriltag_grid (ids row-major)
  std::vector<int> tag_ids;  ///< apriltag: restrict to these ids (empty = all)
  double marker_size = 0.0;  ///< charuco: ArUco marker edge (m)
  std::string dictionary = "DICT_5X5_100";  ///< charuco: OpenCV ArUco dictionary name

  /// Throws InvalidInput naming the field when inconsistent.
  void validate(const std::string& where = "board") const;
  /// Corners (chessboard, charuco: inner corners by id), circle centres or tag corners, in the
  /// board frame (z = 0).
  std::vector<cv::Point3f> objectPoints() const;
  /// One line describing the board for reports ("chessboard 9x6, 0.025 m").
  std::string describe() const;
};

/// The board-file spelling of a type ("chessboard", "circles_grid", "apriltag_grid", "charuco", ...).
std::string toString(BoardType t);
/// Reads a board from a config node (keys above); marks them read.
BoardSpec readBoard(const io::ConfigNode& node);
/// Reads a board file and rejects unknown keys.
BoardSpec loadBoard(const std::string& path);

/// One detected view of a board: matching image and board points.
struct BoardObservation {
  std::vector<cv::Point2f> image_points;  ///< detected pixels (sub-pixel), same order as object_points
  std::vector<cv::Point3f> object_points;  ///< matching points in the board frame (z = 0), m
  std::vector<int> tag_ids;  ///< apriltag*: id of each group of 4 points (same order)
  std::vector<int> corner_ids;  ///< charuco: inner corner id of each point (same order)
};

/// Detection outcome: observation when found, else a reason ("chessboard 9x6 not found").
struct Detection {
  std::optional<BoardObservation> observation;  ///< the matched points when the board was found
  std::string reason;  ///< why it was not found (empty when found)
};

/// Detects the board in an 8-bit grey image. Chessboard corners are refined to sub-pixel.
/// apriltag_grid: uses the tags of the grid that are seen (at least 2 tags).
/// charuco: the inner corners interpolated from the markers seen (at least 6, not all on one line),
/// with their object points by corner id (corner_ids).
Detection detectBoard(const cv::Mat& gray, const BoardSpec& board);

/// Every tag seen in the image (any id, or the spec's tag_ids): id -> 4 corners (ViSP order).
std::map<int, std::vector<cv::Point2f>> detectAprilTags(const cv::Mat& gray, const std::string& family);
/// The 4 corners of a single tag of edge `size` in its own frame (centre origin), ViSP's order.
std::vector<cv::Point3f> tagCorners3d(double size);

/// OpenCV's ArUco dictionary of that name (DICT_5X5_100, ...); InvalidInput listing the names.
cv::Ptr<cv::aruco::Dictionary> arucoDictionary(const std::string& name);
/// OpenCV's model of a charuco board spec (validated; InvalidInput for other board types).
cv::Ptr<cv::aruco::CharucoBoard> charucoBoard(const BoardSpec& board);

/// Reads an image as 8-bit grey; throws InvalidInput naming the file when unreadable.
cv::Mat readGray(const std::string& path);

}  // namespace viewline::calib
