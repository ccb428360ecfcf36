#include <gtest/gtest.h>

#include <limits>

#include "viewline/core/random.h"
#include "viewline/estimation/fixed_kalman.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/ballistic.h"

using namespace viewline;
using namespace viewline::estimation;

namespace {

// The 6-state ballistic filter with M random measurement rows and a diagonal R, in both forms.
template <int M>
struct Problem {
  LinearTransition tr;
  LinearMeasurement meas;
  FixedTransition<6, 1> ftr;
  FixedMeasurement<6, M> fmeas;
};

template <int M>
Problem<M> makeProblem(core::Rng& rng) {
  Problem<M> pb;
  BallisticModel model;
  model.q = 0.5;
  pb.tr = model.transition(0.02);
  pb.ftr.Phi = pb.tr.Phi;
  pb.ftr.Gamma = pb.tr.Gamma;
  pb.ftr.u = pb.tr.u;
  pb.ftr.Q = pb.tr.Q;
  pb.ftr.dt = pb.tr.dt;
  pb.meas.C = Eigen::MatrixXd(M, 6);
  pb.meas.y = Eigen::VectorXd(M);
  pb.meas.R = Eigen::MatrixXd::Zero(M, M);
  for (int r = 0; r < M; ++r) {
    for (int c = 0; c < 6; ++c) pb.meas.C(r, c) = core::gaussian(rng);
    pb.meas.y[r] = core::gaussian(rng);
    pb.meas.R(r, r) = 0.01 * (1.0 + r);
  }
  pb.fmeas.C = pb.meas.C;
  pb.fmeas.y = pb.meas.y;
  pb.fmeas.R = pb.meas.R;
  return pb;
}

double relDiff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).cwiseAbs().maxCoeff() / std::max(1.0, b.cwiseAbs().maxCoeff());
}

template <int M>
void compareOverSteps() {
  core::Rng rng = core::makeRng(7 + M);
  const Problem<M> pb = makeProblem<M>(rng);
  Eigen::VectorXd x0(6);
  x0 << 0.1, -0.2, 3.0, 1.0, 0.5, -2.0;
  StateEstimate dyn(x0, 4.0 * Eigen::MatrixXd::Identity(6, 6), 1.0);
  FixedEstimate<6> fix = FixedEstimate<6>::fromState(dyn);
  for (int k = 0; k < 50; ++k) {
    predict(dyn, pb.tr);
    predict(fix, pb.ftr);
    const UpdateReport rd = update(dyn, pb.meas);
    const FixedUpdateReport<M> rf = update(fix, pb.fmeas);
    ASSERT_LT(relDiff(fix.x, dyn.x()), 1e-12) << "step " << k;
    ASSERT_LT(relDiff(fix.P(), dyn.P()), 1e-12) << "step " << k;
    ASSERT_LT(relDiff(rf.innovation, rd.innovation), 1e-12) << "step " << k;
    ASSERT_LT(relDiff(rf.S, rd.S), 1e-12) << "step " << k;
    ASSERT_NEAR(rf.nis, rd.nis, 1e-12 * std::max(1.0, rd.nis)) << "step " << k;
    ASSERT_DOUBLE_EQ(fix.t, dyn.t());
  }
  // The factor stays lower triangular with a non-negative diagonal.
  EXPECT_EQ(fix.L.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0);
  EXPECT_GE(fix.L.diagonal().minCoeff(), 0.0);
}

}  // namespace

TEST(FixedKalman, MatchesDynamicPathWithTwoRows) { compareOverSteps<2>(); }

TEST(FixedKalman, MatchesDynamicPathWithEightRows) { compareOverSteps<8>(); }

TEST(FixedKalman, RoundTripsThroughStateEstimate) {
  Eigen::VectorXd x0(6);
  x0 << 1, 2, 3, 4, 5, 6;
  Eigen::MatrixXd P0 = Eigen::MatrixXd::Identity(6, 6);
  P0(0, 1) = P0(1, 0) = 0.3;
  const StateEstimate s(x0, P0, 2.5);
  const StateEstimate back = FixedEstimate<6>::fromState(s).toState();
  EXPECT_LT(relDiff(back.P(), P0), 1e-15);
  EXPECT_EQ(back.x(), x0);
  EXPECT_EQ(back.t(), 2.5);
  EXPECT_THROW(FixedEstimate<4>::fromState(s), core::InvalidInput);
}

TEST(FixedKalman, RejectsBadInputAndLeavesTheStateUnchanged) {
  core::Rng rng = core::makeRng(3);
  const Problem<2> pb = makeProblem<2>(rng);
  FixedEstimate<6> s;
  s.x.setOnes();
  s.L = Eigen::Matrix<double, 6, 6>::Identity();
  const FixedEstimate<6> before = s;
  const double nan = std::numeric_limits<double>::quiet_NaN();

  auto tr = pb.ftr;
  tr.Phi(2, 3) = nan;
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  tr = pb.ftr;
  tr.Q(0, 1) += 1.0;  // not symmetric
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  tr = pb.ftr;
  tr.Q(0, 0) = -1.0;  // not positive semi-definite
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  tr = pb.ftr;
  tr.dt = -0.01;
  EXPECT_THROW(predict(s, tr), core::InvalidInput);
  tr = pb.ftr;
  tr.u[0] = nan;
  EXPECT_THROW(predict(s, tr), core::InvalidInput);

  auto m = pb.fmeas;
  m.y[1] = nan;
  EXPECT_THROW(update(s, m), core::InvalidInput);
  m = pb.fmeas;
  m.R(1, 1) = 0.0;  // semi-definite: refused for R
  EXPECT_THROW(update(s, m), core::InvalidInput);
  m = pb.fmeas;
  m.C(0, 0) = nan;
  EXPECT_THROW(update(s, m), core::InvalidInput);

  EXPECT_EQ(s.x, before.x);
  EXPECT_EQ(s.L, before.L);
  EXPECT_EQ(s.t, before.t);

  // A semi-definite Q is accepted (the ballistic model with q = 0 has Q = 0).
  tr = pb.ftr;
  tr.Q.setZero();
  EXPECT_NO_THROW(predict(s, tr));
}
