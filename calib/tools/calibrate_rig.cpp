// calibrate-rig: poses of several calibrated cameras in one world frame from shared board views.
//   calibrate-rig --config rig_calibration.yaml --output rig/rig.yaml
// Config (paths relative to it):
//   board: board.yaml
//   cameras:
//     - name: left
//       intrinsics: left.xml          # ViSP XML from calibrate-camera (camera_name = name); goes into the rig
//       opencv_intrinsics: left.yaml  # optional: OpenCV model used for the poses (more accurate)
//       images: [l01.jpg, l02.jpg]    # one per instant, same order for every camera
//   world:
//     anchor: camera                  # camera | board | apriltag
//     camera: left                    # anchor camera (default: the first)
//     view: 0                         # board/apriltag: the instant whose board/tag defines the world
//     tag_id: 0                       # apriltag: id, tag_size, tag_family (default 36h11)
//     tag_size: 0.1
//     frame: ground                   # board/apriltag: ground (z up) | board (the board's own frame)
//     w_M_anchor:                     # optional: the anchor's (surveyed) pose in the world, when the
//       translation: [..]             # world origin is not on the anchor (default: identity, world =
//       rotation: [[..], [..], [..]]  # anchor frame); {translation, rotation | theta_u_deg}
//     views: [0, 3, 7]                # board: several surveyed placements instead of `view` +
//     w_M_anchors: [{..}, {..}, {..}] # `w_M_anchor` (one pose each, same order): the world is then
//                                     # the least-squares rigid fit (Umeyama) of the boards' outer
//                                     # corners, estimated vs surveyed, which averages out the error
//                                     # of a single board's pose
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/calib/synthetic.h"  // boardOutline
#include "viewline/io/rig.h"

int main(int argc, char** argv) {
  CLI::App app{"Rig extrinsics: every camera's pose in one world frame from shared board views."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string config, output;
  app.add_option("--config", config, "rig calibration config (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--output", output, "rig file to write (with one <camera>.xml per camera next to it)")->required();
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("calibrate-rig", [&] {
    using namespace viewline;
    const auto cfg = io::ConfigNode::loadFile(config);
    const calib::BoardSpec board = calib::loadBoard(cfg.getPath("board"));
    std::vector<core::Camera> cameras;
    calib::RigObservations obs;
    std::vector<std::vector<std::string>> images;
    for (const auto& c : cfg.childList("cameras")) {
      core::Camera cam;
      cam.name = c.get<std::string>("name");
      const auto xml = io::loadVispCameraXml(c.getPath("intrinsics"), cam.name, io::Projection::WithDistortion);
      cam.intrinsics = xml.intrinsics;
      cam.width = xml.width;
      cam.height = xml.height;
      obs.cameras.push_back(c.has("opencv_intrinsics")
                                ? calib::PoseCamera::fromOpenCv(io::loadOpenCvIntrinsics(c.getPath("opencv_intrinsics")))
                                : calib::PoseCamera::fromVisp(cam.intrinsics));
      std::vector<std::string> files = c.get<std::vector<std::string>>("images");
      const std::string dir = std::filesystem::path(c.fileName()).parent_path().string();
      for (auto& f : files)
        if (!f.empty() && f[0] != '/' && !dir.empty()) f = dir + "/" + f;
      if (!images.empty() && files.size() != images.front().size())
        c.fail("images", "as many images as the first camera (" + std::to_string(images.front().size()) + ")");
      images.push_back(files);
      cameras.push_back(cam);
    }
    if (cameras.size() < 2) cfg.fail("cameras", "at least two cameras");
    const auto world = cfg.child("world");
    const std::string anchor = world.getChoice("anchor", {"camera", "board", "apriltag"});
    std::size_t ref = 0;
    if (world.has("camera")) {
      const std::string n = world.get<std::string>("camera");
      ref = cameras.size();
      for (std::size_t i = 0; i < cameras.size(); ++i)
        if (cameras[i].name == n) ref = i;
      if (ref == cameras.size()) world.fail("camera", "the name of one of the cameras");
    }
    const std::size_t view = world.getOr<unsigned>("view", 0);
    if (view >= images.front().size()) world.fail("view", "an instant index below the number of images");
    const std::string frame = anchor == "camera" ? "camera" : world.getChoiceOr("frame", {"ground", "board"}, "ground");
    calib::BoardSpec tag;
    tag.type = calib::BoardType::AprilTag;
    int tag_id = 0;
    if (anchor == "apriltag") {
      tag_id = world.get<int>("tag_id");
      tag.tag_size = world.get<double>("tag_size");
      tag.tag_family = world.getChoiceOr("tag_family", {"36h11", "25h9", "16h5", "circle21h7"}, "36h11");
      tag.tag_ids = {tag_id};
    }
    const Eigen::Isometry3d w_M_anchor = world.has("w_M_anchor") ? io::readPose(world.child("w_M_anchor")) : Eigen::Isometry3d::Identity();
    if (anchor == "camera" && world.has("w_M_anchor")) world.fail("w_M_anchor", "no anchor pose with anchor: camera (the world is that camera's frame)");
    std::vector<std::size_t> anchor_views;
    std::vector<Eigen::Isometry3d> w_M_anchors;
    if (world.has("views")) {
      if (anchor != "board") world.fail("views", "several anchor views only with anchor: board");
      if (world.has("view") || world.has("w_M_anchor")) world.fail("views", "either view + w_M_anchor or views + w_M_anchors");
      for (int v : world.get<std::vector<int>>("views")) {
        if (v < 0 || static_cast<std::size_t>(v) >= images.front().size())
          world.fail("views", "instant indices below the number of images");
        anchor_views.push_back(static_cast<std::size_t>(v));
      }
      for (const auto& n : world.childList("w_M_anchors")) w_M_anchors.push_back(io::readPose(n));
      if (anchor_views.size() < 2 || w_M_anchors.size() != anchor_views.size())
        world.fail("w_M_anchors", "one surveyed pose per entry of views (at least two)");
    }
    cfg.finish();

    const std::size_t nk = images.front().size();
    obs.views.assign(nk, std::vector<std::optional<calib::BoardObservation>>(cameras.size()));
    std::optional<Eigen::Isometry3d> c_M_anchor;
    std::size_t anchor_cam = 0;
    for (std::size_t k = 0; k < nk; ++k)
      for (std::size_t i = 0; i < cameras.size(); ++i) {
        const cv::Mat gray = calib::readGray(images[i][k]);
        if (gray.cols != static_cast<int>(cameras[i].width) || gray.rows != static_cast<int>(cameras[i].height))
          throw core::InvalidInput(images[i][k] + ": image size differs from the intrinsics of camera '" + cameras[i].name + "'");
        const calib::Detection d = calib::detectBoard(gray, board);
        if (d.observation) obs.views[k][i] = d.observation;
        else std::cout << images[i][k] << ": " << d.reason << "\n";
        if (anchor == "apriltag" && k == view && !c_M_anchor) {
          const auto tags = calib::estimateTagPoses(obs.cameras[i], gray, tag);
          if (tags.count(tag_id)) {
            c_M_anchor = tags.at(tag_id).c_M_o;  // ViSP's tag frame: z out of the paper (up on the floor)
            anchor_cam = i;
          }
        }
      }
    const calib::RigResult r = calib::calibrateRig(obs, ref);
    // World frame: w_M_ref.
    Eigen::Isometry3d ref_M_w = Eigen::Isometry3d::Identity();
    if (anchor == "board" && !anchor_views.empty()) {
      // Outer corners of every anchor board, in the reference camera (estimated) and in the world
      // (surveyed): the rigid transform world -> reference that fits them best.
      const Eigen::Isometry3d a_M_b = frame == "ground" ? calib::groundFromBoard(board.type).inverse() : Eigen::Isometry3d::Identity();
      const auto outline = calib::boardOutline(board);
      Eigen::Matrix3Xd in_w(3, 0), in_ref(3, 0);
      for (std::size_t a = 0; a < anchor_views.size(); ++a) {
        const std::size_t v = anchor_views[a];
        bool seen = false;
        for (std::size_t i = 0; i < cameras.size(); ++i) seen = seen || obs.views[v][i].has_value();
        if (!seen) throw core::InvalidInput("world.views: no camera sees the board at instant " + std::to_string(v));
        for (const auto& o : outline) {
          in_w.conservativeResize(3, in_w.cols() + 1);
          in_ref.conservativeResize(3, in_ref.cols() + 1);
          in_w.col(in_w.cols() - 1) = w_M_anchors[a] * (a_M_b * o);
          in_ref.col(in_ref.cols() - 1) = r.ref_M_board[v] * o;
        }
      }
      ref_M_w.matrix() = Eigen::umeyama(in_w, in_ref, false);
      double rms = 0.0;
      for (Eigen::Index c = 0; c < in_w.cols(); ++c) rms += (ref_M_w * in_w.col(c) - in_ref.col(c)).squaredNorm();
      std::cout << "world from " << anchor_views.size() << " surveyed boards: corner fit RMS "
                << 1e3 * std::sqrt(rms / static_cast<double>(in_w.cols())) << " mm; with a free scale: "
                << Eigen::umeyama(in_w, in_ref, true).topLeftCorner<3, 3>().determinant() << "^(1/3) (1 = no scale error)\n";
    } else if (anchor == "board") {
      bool seen = false;
      for (std::size_t i = 0; i < cameras.size(); ++i) seen = seen || obs.views[view][i].has_value();
      if (!seen) throw core::InvalidInput("world.view " + std::to_string(view) + ": no camera sees the board at that instant");
      ref_M_w = r.ref_M_board[view];
      if (frame == "ground") ref_M_w = ref_M_w * calib::groundFromBoard(board.type);
    } else if (anchor == "apriltag") {
      if (!c_M_anchor)
        throw core::InvalidInput("world: tag " + std::to_string(tag_id) + " not seen by any camera at instant " + std::to_string(view));
      // A single tag's ViSP frame already has z out of the paper (up, on the floor).
      ref_M_w = r.c_M_ref[anchor_cam].inverse() * *c_M_anchor;
    }
    ref_M_w = ref_M_w * w_M_anchor.inverse();
    for (std::size_t i = 0; i < cameras.size(); ++i) {
      cameras[i].c_M_w = r.c_M_ref[i] * ref_M_w;
      std::cout << cameras[i].name << ": " << r.views_used[i] << " views, RMS " << r.camera_rms_px[i]
                << " px, centre in world [" << cameras[i].center_w().transpose() << "] m\n";
    }
    std::cout << "overall RMS " << r.rms_px << " px; baseline " << cameras[0].name << "-" << cameras[1].name << " "
              << (cameras[0].center_w() - cameras[1].center_w()).norm() << " m\n";
    std::ostringstream comment;
    comment << "calibrate-rig from " << config << ": world anchor " << anchor << ", RMS " << r.rms_px << " px";
    for (const auto& f : io::saveRig(output, cameras, comment.str())) std::cout << "wrote " << f << "\n";
    return 0;
  });
}
