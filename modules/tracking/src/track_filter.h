#pragma once
// The viewline tracker's filter state with the optional per-camera pixel bias (tracker.h, "Pixel
// bias"): x = (p, v) without it, x = (p, v, b_0, ..., b_{C−1}) (b_c in px) with it. Shared by
// tracker.cpp and track_start.cpp; only used when TrackerConfig::pixel_bias is on (the (p, v)
// code paths stay as they were, so the option off is bit-identical). In TimeMode::DtOffset an
// image Δt after the grid instant sees the bias at the grid instant (b(t + Δt) = b(t) for Δt ≪ τ).

#include "viewline/tracking/tracker.h"

namespace viewline::tracking::detail {

/// Index of camera c's first bias entry in the augmented state.
inline Eigen::Index biasIndex(std::size_t camera) { return 6 + 2 * static_cast<Eigen::Index>(camera); }

/// The prior of a new track at t: (p, v) from the config and every camera's bias at its
/// stationary prior N(0, σ_b² I), independent of (p, v) (tracker.h: biases restart per track).
estimation::StateEstimate biasedPrior(const TrackerConfig& cfg, std::size_t cameras, core::Timestamp t);

/// Time update of the augmented state over dt >= 0: ballistic (p, v), and per bias axis
/// b ← a b, a = e^{−dt/τ}, Q_b = σ_b² (1 − a²) (exact discretisation of ḃ = −b/τ + w).
void predictBiased(const TrackerConfig& cfg, estimation::StateEstimate& s, double dt);

/// The (p, v) part of an augmented state's mean.
inline Vector6 meanPV(const estimation::StateEstimate& s) { return s.x().head<6>(); }
/// The (p, v) marginal covariance (from the first 6 rows of the lower-triangular factor).
Matrix6 covPV(const estimation::StateEstimate& s);
/// The (p, v) marginal of an augmented state (exact: L's top-left 6 x 6 block factors P_pv).
estimation::StateEstimate marginalPV(const estimation::StateEstimate& s);

/// The image's two rows on the augmented state: rows.C on (p, v) and ∂/∂b_c = −√E[Z²] D J
/// (viewlinePixelJacobian) on the image's camera; R = rows.R (the white part).
estimation::LinearMeasurement biasedMeasurement(const estimation::StateEstimate& s, const core::Camera& camera,
                                                const ImageMeasurement& m, const ViewlineRows& rows,
                                                double depth_sq);

}  // namespace viewline::tracking::detail
