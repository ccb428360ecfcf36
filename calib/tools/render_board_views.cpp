// render-board-views: synthetic calibration images of a board, rendered by the simulator through the
// true rig of a truth file (calib/rigs/<rig>/truth.yaml), for the calibration tools to estimate from.
//   render-board-views --truth truth.yaml --board board.yaml --mode intrinsics --camera side --views 15 --seed 1 --output-dir DIR
// Modes (files written in DIR, PNG, 8-bit grey):
//   intrinsics  <camera>_NN.png: the board close up at varied poses (camera --camera, or every camera).
//   rig         <camera>_NN.png for every camera at shared instants (board seen fully by all), and
//               rig_calibration.yaml, the calibrate-rig config; its world anchor is the board of
//               instant 0 at its (surveyed) world pose, so the calibrated rig is in the truth's world.
//               Needs --intrinsics-dir: where calibrate-camera wrote <camera>.xml and <camera>.yaml.
//               With --reference CAM (rigs whose cameras cannot all see one board, e.g. cameras on
//               opposite sides of the scene): each instant is seen fully by CAM and by one partner
//               camera, the partners taken in turn, so every camera shares views with CAM (what
//               calibrate-rig needs; the config names CAM as its reference). Every camera's image
//               is still rendered at every instant: the others see the board obliquely, partly or
//               not at all, and calibrate-rig uses whatever the detector finds in them.
//               --surveyed N: the boards of the first N instants are anchors at surveyed world poses
//               (default 1); calibrate-rig then fits the world to all of them.
//   ground      <camera>_ground_NN.png: the board lying on the floor at --floor-origin (camera still).
//   hand-eye    <camera>_ptu_NN.png and robot_poses.yaml (r_M_e per image, the PTU's forward
//               kinematics): the board fixed in the PTU base frame, the camera on the PTU (truth's
//               hand_eye.e_M_c) at varied pan/tilt angles.
// truth_poses.yaml records the true board poses (for checking only; the tools never read it).
#include <CLI/CLI.hpp>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "tool_common.h"
#include "viewline/core/version.h"
#include "viewline/calib/synthetic.h"
#include "viewline/core/frames.h"
#include "viewline/io/files.h"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  CLI::App app{"Renders calibration-board images through the true rig of a truth file (simulator renderer,\n"
               "ViSP kud distortion, blur, sensor noise)."};
  app.set_version_flag("--version", std::string("viewline ") + viewline::core::kVersion);
  std::string truth_file, board_file, mode = "intrinsics", camera, out_dir, intrinsics_dir, reference;
  int views = 15, surveyed = 1;
  std::uint64_t seed = 1;
  std::vector<double> target, floor_origin{0.0, 0.0}, board_in_front{0.75, 0.0765, 0.068};
  double radius = 0.4, max_obliquity_deg = 65.0, pan_range_deg = 20.0, tilt_range_deg = 15.0;
  app.add_option("--truth", truth_file, "truth file (calib/rigs/<rig>/truth.yaml)")->required()->check(CLI::ExistingFile);
  app.add_option("--board", board_file, "board description (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--mode", mode, "intrinsics | rig | ground | hand-eye")
      ->check(CLI::IsMember({"intrinsics", "rig", "ground", "hand-eye"}));
  app.add_option("--camera", camera, "camera of the truth file (intrinsics: default every camera; ground, hand-eye: default the first)");
  app.add_option("--views", views, "number of views (instants)")->check(CLI::Range(1, 500));
  app.add_option("--seed", seed, "random seed (poses and noise)");
  app.add_option("--output-dir", out_dir, "directory for the images")->required();
  app.add_option("--intrinsics-dir", intrinsics_dir, "rig: directory of the calibrated <camera>.xml/.yaml");
  app.add_option("--target", target, "rig: centre of the shared views, world x y z (default: the point closest to the optical axes)")
      ->expected(3);
  app.add_option("--reference", reference,
                 "rig: every instant seen fully by this camera and one partner in turn (default: by every camera)");
  app.add_option("--surveyed", surveyed, "rig: the first N instants' boards anchor the world at surveyed poses")
      ->check(CLI::PositiveNumber);
  app.add_option("--radius", radius, "rig: board centres within +-radius of the target per axis, m");
  app.add_option("--max-obliquity", max_obliquity_deg, "rig: largest angle between board normal and line of sight, deg");
  app.add_option("--floor-origin", floor_origin, "ground: board origin on the floor, world x y (m)")->expected(2);
  app.add_option("--board-position", board_in_front, "hand-eye: board centre in the PTU base frame, x y z (m)")
      ->expected(3);
  app.add_option("--pan-range", pan_range_deg, "hand-eye: pan angles within +-this, deg");
  app.add_option("--tilt-range", tilt_range_deg, "hand-eye: tilt angles within +-this, deg");
  if (const auto code = viewline::calib::tools::parseCommandLine(app, argc, argv)) return *code;
  return viewline::calib::tools::runTool("render-board-views", [&] {
    using namespace viewline;
    const calib::RigTruth truth = calib::loadRigTruth(truth_file);
    const calib::BoardSpec board = calib::loadBoard(board_file);
    core::Rng rng = core::makeRng(seed);
    fs::create_directories(out_dir);
    std::ostringstream poses;
    poses << std::setprecision(10) << "# render-board-views --mode " << mode << " --seed " << seed << ": true board poses (checking only)\n";
    auto name = [&](const std::string& cam, const std::string& tag, int k) {
      std::ostringstream s;
      s << out_dir << "/" << cam << tag << "_" << std::setw(2) << std::setfill('0') << k << ".png";
      return s.str();
    };
    auto write = [&](const std::string& file, const cv::Mat& img) {
      if (!cv::imwrite(file, img)) throw core::InvalidInput(file + ": cannot write the image");
    };
    std::size_t written = 0;
    if (mode == "intrinsics") {
      poses << "c_M_o:\n";
      for (const auto& cam : truth.cameras) {
        if (!camera.empty() && cam.name != camera) continue;
        const auto ps = calib::sampleIntrinsicsPoses(cam, board, views, rng);
        poses << "  " << cam.name << ":\n";
        for (int k = 0; k < views; ++k) {
          write(name(cam.name, "", k), calib::renderBoardImage(cam, ps[static_cast<std::size_t>(k)], board, truth.imaging, rng));
          poses << "    -\n" << calib::tools::poseYaml(ps[static_cast<std::size_t>(k)], 6);
          ++written;
        }
      }
      if (written == 0) throw core::InvalidInput("--camera: no camera named '" + camera + "' in " + truth_file);
    } else if (mode == "rig") {
      if (truth.cameras.size() < 2) throw core::InvalidInput(truth_file + ": mode rig needs at least two cameras");
      if (intrinsics_dir.empty()) throw core::InvalidInput("mode rig: give --intrinsics-dir (calibrate-camera's output)");
      calib::RigViewOptions o;
      o.center_w = target.size() == 3 ? Eigen::Vector3d(target[0], target[1], target[2]) : calib::commonViewPoint(truth.cameras);
      o.radius = radius;
      o.max_obliquity_rad = core::deg2rad(max_obliquity_deg);
      std::cout << "shared views around [" << o.center_w.transpose() << "] m\n";
      std::vector<Eigen::Isometry3d> ps;
      if (reference.empty()) {
        ps = calib::sampleRigPoses(truth.cameras, board, views, rng, o);
      } else {
        const core::Camera& ref = truth.camera(reference);
        std::vector<const core::Camera*> partners;
        for (const auto& cam : truth.cameras)
          if (cam.name != reference) partners.push_back(&cam);
        for (int k = 0; k < views; ++k) {
          const std::vector<core::Camera> pair{ref, *partners[static_cast<std::size_t>(k) % partners.size()]};
          calib::RigViewOptions op = o;
          if (target.size() != 3) op.center_w = calib::commonViewPoint(pair);
          ps.push_back(calib::sampleRigPoses(pair, board, 1, rng, op).front());
          std::cout << "instant " << k << ": " << pair[0].name << " + " << pair[1].name << " around ["
                    << op.center_w.transpose() << "] m\n";
        }
      }
      std::ostringstream cfg;
      cfg << std::setprecision(10) << "# calibrate-rig config written by render-board-views (seed " << seed << ")\n"
          << "board: " << fs::absolute(board_file).string() << "\ncameras:\n";
      for (const auto& cam : truth.cameras) {
        cfg << "  - name: " << cam.name << "\n    intrinsics: " << fs::absolute(intrinsics_dir + "/" + cam.name + ".xml").string()
            << "\n    opencv_intrinsics: " << fs::absolute(intrinsics_dir + "/" + cam.name + ".yaml").string() << "\n    images:\n";
        for (int k = 0; k < views; ++k) {
          const std::string f = name(cam.name, "", k);
          write(f, calib::renderBoardImage(cam, cam.c_M_w * ps[static_cast<std::size_t>(k)], board, truth.imaging, rng));
          cfg << "      - " << fs::absolute(f).string() << "\n";
          ++written;
        }
      }
      // World anchor: the board of instant 0 (or of the first --surveyed instants), whose world pose
      // was surveyed (here: the truth).
      if (surveyed > views) throw core::InvalidInput("--surveyed: more than --views");
      cfg << "world:\n  anchor: board\n  frame: board\n";
      if (!reference.empty()) cfg << "  camera: " << reference << "\n";
      if (surveyed == 1) {
        cfg << "  view: 0\n  w_M_anchor:\n" << calib::tools::poseYaml(ps.front(), 4);
      } else {
        cfg << "  views: [";
        for (int k = 0; k < surveyed; ++k) cfg << (k ? ", " : "") << k;
        cfg << "]\n  w_M_anchors:\n";
        for (int k = 0; k < surveyed; ++k) cfg << "    -\n" << calib::tools::poseYaml(ps[static_cast<std::size_t>(k)], 6);
      }
      io::writeTextFileAtomic(out_dir + "/rig_calibration.yaml", cfg.str());
      std::cout << "wrote " << out_dir << "/rig_calibration.yaml\n";
      poses << "w_M_o:\n";
      for (const auto& p : ps) poses << "  -\n" << calib::tools::poseYaml(p, 4);
    } else {
      const core::Camera& cam = camera.empty() ? truth.cameras.front() : truth.camera(camera);
      if (mode == "ground") {
        const Eigen::Isometry3d w_M_o = calib::floorBoardPose(board, Eigen::Vector2d(floor_origin[0], floor_origin[1]));
        if (!calib::boardFullyVisible(cam, cam.c_M_w * w_M_o, board, 2.0, core::deg2rad(80.0)))
          throw core::InvalidInput("--floor-origin: the floor board is not fully visible from camera '" + cam.name + "'");
        for (int k = 0; k < views; ++k) {
          write(name(cam.name, "_ground", k), calib::renderBoardImage(cam, cam.c_M_w * w_M_o, board, truth.imaging, rng));
          ++written;
        }
        poses << "w_M_o:\n" << calib::tools::poseYaml(w_M_o, 2);
      } else {  // hand-eye
        if (!truth.e_M_c) throw core::InvalidInput(truth_file + ": mode hand-eye needs a hand_eye section (e_M_c)");
        // Board fixed in the PTU base frame f (x forward, z up), facing the camera at q = 0.
        Eigen::Isometry3d f_M_o = Eigen::Isometry3d::Identity();
        f_M_o.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // board x = -y_f, y = -z_f, z = +x_f (away from the camera)
        const auto outline = calib::boardOutline(board);
        f_M_o.translation() = Eigen::Vector3d(board_in_front[0], board_in_front[1], board_in_front[2]) - f_M_o.linear() * (0.5 * (outline[0] + outline[2]));
        std::ostringstream robot;
        robot << std::setprecision(12) << "# render-board-views --mode hand-eye: PTU end effector in its base frame (vpPtu46 kinematics)\nposes:\n";
        poses << "f_M_o:\n" << calib::tools::poseYaml(f_M_o, 2) << "q_deg:\n";
        int k = 0;
        for (int attempt = 0; k < views; ++attempt) {
          if (attempt > 1000 * views) throw core::NumericalError("hand-eye: no PTU pose sees the whole board; move it (--board-position) or narrow --pan-range/--tilt-range");
          // First pose at home; then alternate pan-dominant and tilt-dominant moves.
          const Eigen::Vector2d q = k == 0 ? Eigen::Vector2d::Zero()
                                           : Eigen::Vector2d(core::deg2rad(core::uniform(rng, -pan_range_deg, pan_range_deg)),
                                                             core::deg2rad(core::uniform(rng, -tilt_range_deg, tilt_range_deg)));
          const Eigen::Isometry3d f_M_e = calib::ptuBaseToEffector(q);
          const Eigen::Isometry3d c_M_o = (f_M_e * *truth.e_M_c).inverse() * f_M_o;
          if (!calib::boardFullyVisible(cam, c_M_o, board, 6.0, core::deg2rad(60.0))) continue;
          write(name(cam.name, "_ptu", k), calib::renderBoardImage(cam, c_M_o, board, truth.imaging, rng));
          robot << "  - q_deg: [" << core::rad2deg(q.x()) << ", " << core::rad2deg(q.y()) << "]\n    r_M_e:\n"
                << calib::tools::poseYaml(f_M_e, 6);
          poses << "  - [" << core::rad2deg(q.x()) << ", " << core::rad2deg(q.y()) << "]\n";
          ++k;
          ++written;
        }
        io::writeTextFileAtomic(out_dir + "/robot_poses.yaml", robot.str());
        std::cout << "wrote " << out_dir << "/robot_poses.yaml\n";
      }
    }
    io::writeTextFileAtomic(out_dir + "/truth_poses_" + mode + (camera.empty() ? "" : "_" + camera) + ".yaml", poses.str());
    std::cout << "wrote " << written << " images to " << out_dir << "\n";
    return 0;
  });
}
