// Estimation core against its peers, same process, same data: one predict + update of the
// 6-state ballistic filter ([L] eqs 1-10) with 2 rows (one image's viewline planes) and with
// 8 rows (four cameras), for
//  - ours, fixed size (estimation/fixed_kalman.h): square-root array algorithm on Eigen
//    fixed-size matrices, every input validated on every call;
//  - ours, dynamic size (estimation/kalman_filter.h), the same algorithm and validation;
//  - cv::KalmanFilter(6, m, 1, CV_64F): predict(control) with Γ and u = 1, correct(y)
//    (covariance form, cv::solve), no validation;
//  - vpKalmanFilter::init(6, m, 1): prediction() and filtering(y) (explicit inverse), no control
//    input (a little less work than the others), no validation.
// Φ, Γ, Q come from estimation::BallisticModel (q = 1, dt = 20 ms); the rows C are viewline planes
// of 1 and 4 cameras around a target at 3 m ([L] eq 26, Δt ≠ 0), y fixed (the work per step does
// not depend on the values).
//
// Timing: batches of `batch` steps timed with the thread CPU clock; the variants take turns batch
// by batch (the same load for all); per-step median and p99 over the batch means (>= 10,000 steps
// per variant: --batches x --batch).
//
//   nice -n 10 build/bench/latency_estimation [--batches 200] [--batch 100]

#include <Eigen/Core>  // before OpenCV's Eigen bridge
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/video/tracking.hpp>
#include <visp3/core/vpKalmanFilter.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "../estimation/ballistic_problem.h"
#include "latency_stats.h"
#include "viewline/estimation/fixed_kalman.h"
#include "viewline/estimation/kalman_filter.h"
#include "viewline/estimation/models/ballistic.h"

namespace {

using namespace viewline;
using namespace viewline::estimation;

volatile double g_sink = 0.0;  // keeps the results alive

using bench::Problem;
using bench::makeProblem;

/// A variant: `run(k)` does k predict + update steps.
struct Variant {
  std::string name;
  std::function<void(int)> run;
  std::vector<double> per_step;  // s, one entry per batch
};

template <int M>
Variant fixedVariant(const Problem& pb) {
  FixedTransition<6, 1> tr;
  tr.Phi = pb.tr.Phi;
  tr.Gamma = pb.tr.Gamma;
  tr.u = pb.tr.u;
  tr.Q = pb.tr.Q;
  tr.dt = pb.tr.dt;
  FixedMeasurement<6, M> m;
  m.C = pb.meas.C;
  m.y = pb.meas.y;
  m.R = pb.meas.R;
  auto s = std::make_shared<FixedEstimate<6>>(FixedEstimate<6>::fromState(StateEstimate(pb.x0, pb.P0)));
  return {"viewline fixed-size", [s, tr, m](int k) {
            for (int i = 0; i < k; ++i) {
              predict(*s, tr);
              g_sink = update(*s, m).nis;
            }
          }, {}};
}

Variant dynamicVariant(const Problem& pb) {
  auto s = std::make_shared<StateEstimate>(pb.x0, pb.P0);
  return {"viewline dynamic-size", [s, pb](int k) {
            for (int i = 0; i < k; ++i) {
              predict(*s, pb.tr);
              g_sink = update(*s, pb.meas).nis;
            }
          }, {}};
}

cv::Mat toCv(const Eigen::MatrixXd& m) {
  cv::Mat out;
  cv::eigen2cv(m, out);
  return out;
}

Variant opencvVariant(const Problem& pb) {
  const int rows = static_cast<int>(pb.meas.y.size());
  auto kf = std::make_shared<cv::KalmanFilter>(6, rows, 1, CV_64F);
  kf->transitionMatrix = toCv(pb.tr.Phi);
  kf->controlMatrix = toCv(pb.tr.Gamma);
  kf->processNoiseCov = toCv(pb.tr.Q);
  kf->measurementMatrix = toCv(pb.meas.C);
  kf->measurementNoiseCov = toCv(pb.meas.R);
  kf->statePost = toCv(pb.x0);
  kf->errorCovPost = toCv(pb.P0);
  const cv::Mat control = toCv(pb.tr.u);
  const cv::Mat y = toCv(pb.meas.y);
  return {"cv::KalmanFilter", [kf, control, y](int k) {
            for (int i = 0; i < k; ++i) {
              kf->predict(control);
              g_sink = kf->correct(y).at<double>(0);
            }
          }, {}};
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

Variant vispVariant(const Problem& pb) {
  const auto rows = static_cast<unsigned int>(pb.meas.y.size());
  auto kf = std::make_shared<vpKalmanFilter>();
  kf->init(6, rows, 1);
  kf->F = toVp(pb.tr.Phi);
  kf->H = toVp(pb.meas.C);
  kf->Q = toVp(pb.tr.Q);
  kf->R = toVp(pb.meas.R);
  kf->Xest = toVpCol(pb.x0);
  kf->Pest = toVp(pb.P0);
  const vpColVector y = toVpCol(pb.meas.y);
  return {"vpKalmanFilter", [kf, y](int k) {
            for (int i = 0; i < k; ++i) {
              kf->prediction();
              kf->filtering(y);
              g_sink = kf->Xest[0];
            }
          }, {}};
}

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  int batches = 200, batch = 100;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (i + 1 < argc && a == "--batches") batches = std::atoi(argv[++i]);
    else if (i + 1 < argc && a == "--batch") batch = std::atoi(argv[++i]);
    else {
      std::fprintf(stderr, "usage: %s [--batches B>=1] [--batch K>=1]\n", argv[0]);
      return 2;
    }
  }
  if (batches < 1 || batch < 1) {
    std::fprintf(stderr, "%s: --batches and --batch must be >= 1\n", argv[0]);
    return 2;
  }
  std::printf("# Estimation core: 6-state ballistic predict + update, per step (thread CPU time, one core); load %s\n",
              latency::loadAverage().c_str());
  std::printf("%d batches of %d steps per variant (per-step median and p99 over the batch means)\n\n", batches, batch);
  bool target = true;
  for (int rows : {2, 8}) {
    const Problem pb = makeProblem(rows);
    std::vector<Variant> vs;
    vs.push_back(rows == 2 ? fixedVariant<2>(pb) : fixedVariant<8>(pb));
    vs.push_back(dynamicVariant(pb));
    vs.push_back(opencvVariant(pb));
    vs.push_back(vispVariant(pb));
    for (auto& v : vs) v.run(batch);  // warm-up (caches, first-call allocations)
    for (int b = 0; b < batches; ++b) {
      for (auto& v : vs) {
        const double t0 = latency::threadCpuNow();
        v.run(batch);
        v.per_step.push_back((latency::threadCpuNow() - t0) / batch);
      }
    }
    std::printf("## %d rows\n\n| implementation | median (us) | p99 (us) | / fastest peer |\n|---|---|---|---|\n", rows);
    std::vector<latency::Stats> st;
    for (auto& v : vs) st.push_back(latency::summarise(v.per_step));
    const double peer = std::min(st[2].median, st[3].median);
    for (std::size_t i = 0; i < vs.size(); ++i)
      std::printf("| %s | %.3f | %.3f | %.2f |\n", vs[i].name.c_str(), 1e6 * st[i].median, 1e6 * st[i].p99,
                  st[i].median / peer);
    const bool met = st[0].median <= 0.5 * peer;
    std::printf("\nfixed-size / fastest peer = %.2f (target <= 0.5: %s)\n\n", st[0].median / peer, met ? "met" : "NOT met");
    target = target && met;
  }
  return target ? 0 : 1;
}
