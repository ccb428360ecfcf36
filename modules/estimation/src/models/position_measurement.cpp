#include "viewline/estimation/models/position_measurement.h"

#include <sstream>

#include "viewline/core/checks.h"

namespace viewline::estimation {

LinearMeasurement positionMeasurement(Eigen::Index state_dim, const Eigen::VectorXd& y, double sigma) {
  const Eigen::Index d = y.size();
  if (d < 1 || d > state_dim) {
    std::ostringstream s;
    s << "positionMeasurement: y has " << d << " entries (expected 1.." << state_dim << ")";
    throw core::InvalidInput(s.str());
  }
  core::requireFinite(y, "positionMeasurement: y");
  core::requirePositive(sigma, "positionMeasurement: sigma");
  LinearMeasurement m;
  m.C = Eigen::MatrixXd::Zero(d, state_dim);
  m.C.leftCols(d).setIdentity();
  m.y = y;
  m.R = sigma * sigma * Eigen::MatrixXd::Identity(d, d);
  return m;
}

}  // namespace viewline::estimation
