// One predict + update of the 6-state ballistic filter ([L] eqs 1-10, docs/methods.md)
// with 2 and with 8 measurement rows, for our square-root filter and, in the
// same run, for cv::KalmanFilter and ViSP's vpKalmanFilter doing the same work.
//
// The same Φ (BallisticModel, dt = 20 ms), Q, C and R are given to all three:
// - ours: estimation::predict (x ← Φx + Γu, square-root time update) and
//   estimation::update (square-root array measurement update, innovation
//   covariance through its triangular factor), with full input validation
//   (finite values, sizes, symmetric positive (semi-)definite Q and R) on
//   every call;
// - OpenCV: cv::KalmanFilter(6, m, 1, CV_64F), predict(control) with
//   controlMatrix Γ and control u = 1 (gravity), then correct(y): covariance
//   form P⁻ = Φ P Φᵀ + Q, K = P⁻Cᵀ(C P⁻Cᵀ + R)⁻¹ (cv::solve), P = P⁻ − K C P⁻;
//   no validation;
// - ViSP: vpKalmanFilter::init(6, m, 1) with its public F, H, Q, R, Xest, Pest
//   set, then prediction() (Xpre = F Xest, Ppre = F Pest Fᵀ + Q) and
//   filtering(y) (W = Ppre Hᵀ (H Ppre Hᵀ + R)⁻¹ with an explicit inverse,
//   Pest = (I − W H) Ppre). vpKalmanFilter has no control input, so its step
//   does not add Γu (slightly less work than the others); no validation.
//
// The rows C are viewline planes ([L] eq 26 with Δt ≠ 0, two per camera) of
// 1 and 4 cameras. The measurement y is fixed; the state converges to it and
// the work per step does not depend on the values.
//
// Run: build/bench/estimation_bench --benchmark_min_time=0.2

#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/video/tracking.hpp>
#include <visp3/core/vpKalmanFilter.h>

#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/ballistic.h"
#include "ballistic_problem.h"

namespace {

using namespace viewline;
using namespace viewline::estimation;

using bench::Problem;
using bench::makeProblem;


void BM_Ours(benchmark::State& state) {
  const Problem pb = makeProblem(static_cast<int>(state.range(0)));
  StateEstimate s(pb.x0, pb.P0);
  for (auto _ : state) {
    predict(s, pb.tr);
    const UpdateReport rep = update(s, pb.meas);
    benchmark::DoNotOptimize(rep.nis);
    benchmark::DoNotOptimize(s.x().data());
  }
}

// Same, but Q and R alternate between two values every step, so the per-thread cache of validated
// factors never hits: every step validates and factors Q and R again (the cost with aperiodic
// samples, where Φ, Q are rebuilt for every interval).
void BM_OursNoCache(benchmark::State& state) {
  const Problem pb = makeProblem(static_cast<int>(state.range(0)));
  LinearTransition tr2 = pb.tr;
  tr2.Q *= 1.01;
  LinearMeasurement m2 = pb.meas;
  m2.R *= 1.01;
  StateEstimate s(pb.x0, pb.P0);
  bool flip = false;
  for (auto _ : state) {
    flip = !flip;
    predict(s, flip ? tr2 : pb.tr);
    const UpdateReport rep = update(s, flip ? m2 : pb.meas);
    benchmark::DoNotOptimize(rep.nis);
    benchmark::DoNotOptimize(s.x().data());
  }
}

cv::Mat toCv(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

void BM_OpenCV(benchmark::State& state) {
  const int rows = static_cast<int>(state.range(0));
  const Problem pb = makeProblem(rows);
  cv::KalmanFilter kf(6, rows, 1, CV_64F);
  kf.transitionMatrix = toCv(pb.tr.Phi);
  kf.controlMatrix = toCv(pb.tr.Gamma);
  kf.processNoiseCov = toCv(pb.tr.Q);
  kf.measurementMatrix = toCv(pb.meas.C);
  kf.measurementNoiseCov = toCv(pb.meas.R);
  kf.statePost = toCv(pb.x0);
  kf.errorCovPost = toCv(pb.P0);
  const cv::Mat control = toCv(pb.tr.u);
  const cv::Mat y = toCv(pb.meas.y);
  for (auto _ : state) {
    kf.predict(control);
    const cv::Mat& x = kf.correct(y);
    benchmark::DoNotOptimize(x.data);
  }
}

vpMatrix toVp(const Eigen::MatrixXd& m) {
  vpMatrix out(static_cast<unsigned int>(m.rows()), static_cast<unsigned int>(m.cols()));
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) out[static_cast<unsigned int>(i)][static_cast<unsigned int>(j)] = m(i, j);
  return out;
}

vpColVector toVpCol(const Eigen::VectorXd& v) {
  vpColVector out(static_cast<unsigned int>(v.size()));
  for (Eigen::Index i = 0; i < v.size(); ++i) out[static_cast<unsigned int>(i)] = v[i];
  return out;
}

void BM_ViSP(benchmark::State& state) {
  const int rows = static_cast<int>(state.range(0));
  const Problem pb = makeProblem(rows);
  vpKalmanFilter kf;
  kf.init(6, static_cast<unsigned int>(rows), 1);
  kf.F = toVp(pb.tr.Phi);
  kf.H = toVp(pb.meas.C);
  kf.Q = toVp(pb.tr.Q);
  kf.R = toVp(pb.meas.R);
  kf.Xest = toVpCol(pb.x0);
  kf.Pest = toVp(pb.P0);
  const vpColVector y = toVpCol(pb.meas.y);
  for (auto _ : state) {
    kf.prediction();
    kf.filtering(y);
    benchmark::DoNotOptimize(kf.Xest.data);
  }
}

}  // namespace

BENCHMARK(BM_Ours)->Arg(2)->Arg(8)->ArgName("rows");
BENCHMARK(BM_OursNoCache)->Arg(2)->Arg(8)->ArgName("rows");
BENCHMARK(BM_OpenCV)->Arg(2)->Arg(8)->ArgName("rows");
BENCHMARK(BM_ViSP)->Arg(2)->Arg(8)->ArgName("rows");

BENCHMARK_MAIN();
