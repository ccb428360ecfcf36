#pragma once
// The benchmark problem shared by the estimation benches: one predict + update of the 6-state
// ballistic filter of [L] with m = 2 x cameras viewline-plane rows (cameras on a circle around a
// point near (0, 0, 3), unsynchronised captures).

#include <Eigen/Core>
#include <cmath>

#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/ballistic.h"

namespace viewline::bench {

struct Problem {
  estimation::LinearTransition tr;
  estimation::LinearMeasurement meas;
  Eigen::VectorXd x0;
  Eigen::MatrixXd P0;
};

// m = 2 * cameras rows: the two viewline planes of each camera through a point near p = (0, 0, 3).
inline Problem makeProblem(int rows) {
  Problem pb;
  estimation::BallisticModel model;
  model.q = 1.0;
  pb.tr = model.transition(0.02);
  const int cameras = rows / 2;
  pb.meas.C = Eigen::MatrixXd::Zero(rows, 6);
  pb.meas.y = Eigen::VectorXd::Zero(rows);
  pb.meas.R = Eigen::MatrixXd::Zero(rows, rows);
  const Eigen::Vector3d target(0.0, 0.0, 3.0);
  for (int c = 0; c < cameras; ++c) {
    // Camera c on a circle looking at the target; its planes contain the viewline.
    const double a = 2.0 * M_PI * c / cameras;
    const Eigen::Vector3d centre(4.0 * std::cos(a), 4.0 * std::sin(a), 1.5);
    const Eigen::Vector3d dir = (target - centre).normalized();
    const Eigen::Vector3d n1 = dir.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d n2 = dir.cross(n1).normalized();
    const double dt_capture = 0.004 * c;  // unsynchronised cameras ([L] eq 26)
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3d n = (k == 0) ? n1 : n2;
      const int r = 2 * c + k;
      pb.meas.C.block<1, 3>(r, 0) = n.transpose();
      pb.meas.C.block<1, 3>(r, 3) = dt_capture * n.transpose();
      pb.meas.y[r] = n.dot(target);
      pb.meas.R(r, r) = std::pow(0.002 * (1.0 + 0.1 * r), 2);
    }
  }
  pb.x0 = (Eigen::VectorXd(6) << 0.1, -0.1, 3.2, 0.0, 0.0, -8.0).finished();
  pb.P0 = Eigen::MatrixXd::Identity(6, 6);
  return pb;
}

}  // namespace viewline::bench
