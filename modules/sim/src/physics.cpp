#include "viewline/sim/physics.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "viewline/core/checks.h"
#include "viewline/core/frames.h"

namespace viewline::sim {

using core::InvalidInput;

namespace {
using core::requireNonNegative;
}  // namespace

double DragBody::dragPerMass() const {
  core::requirePositive(mass, "DragBody.mass");
  core::requirePositive(reference_radius, "DragBody.reference_radius");
  requireNonNegative(drag_coefficient, "DragBody.drag_coefficient");
  requireNonNegative(air_density, "DragBody.air_density");
  return air_density * drag_coefficient * core::kPi * reference_radius * reference_radius / (2.0 * mass);
}

FlightState flightDerivative(const FlightState& s, double k, const Eigen::Vector3d& g_w) {
  return {s.v, g_w - k * s.v.norm() * s.v};
}

FlightState rk4Step(const FlightState& s, double dt, double k, const Eigen::Vector3d& g_w) {
  auto add = [](const FlightState& a, const FlightState& d, double h) {
    return FlightState{a.p + h * d.p, a.v + h * d.v};
  };
  const FlightState k1 = flightDerivative(s, k, g_w);
  const FlightState k2 = flightDerivative(add(s, k1, 0.5 * dt), k, g_w);
  const FlightState k3 = flightDerivative(add(s, k2, 0.5 * dt), k, g_w);
  const FlightState k4 = flightDerivative(add(s, k3, dt), k, g_w);
  return {s.p + dt / 6.0 * (k1.p + 2.0 * k2.p + 2.0 * k3.p + k4.p),
          s.v + dt / 6.0 * (k1.v + 2.0 * k2.v + 2.0 * k3.v + k4.v)};
}

DragFlight::DragFlight(const FlightState& initial, double t0, double duration, const DragBody& body,
                       double step, const Eigen::Vector3d& g_w)
    : t0_(t0), duration_(duration), step_(step), k_(body.dragPerMass()), body_(body), g_w_(g_w) {
  core::requireFinite(initial.p, "DragFlight: initial position");
  core::requireFinite(initial.v, "DragFlight: initial velocity");
  core::requireFinite(t0, "DragFlight: t0");
  core::requirePositive(duration, "DragFlight: duration");
  core::requirePositive(step, "DragFlight: step");
  core::requireFinite(g_w, "DragFlight: gravity");
  const auto n = static_cast<std::size_t>(std::ceil(duration / step)) + 1;
  knots_.reserve(n + 1);
  knots_.push_back(initial);
  for (std::size_t i = 1; i <= n; ++i) knots_.push_back(rk4Step(knots_.back(), step_, k_, g_w_));
}

FlightState DragFlight::state(double t) const {
  core::requireFinite(t, "DragFlight::state: t");
  const double tau = t - t0_;
  if (tau < -1e-12 || tau > duration_ + 1e-12) {
    std::ostringstream s;
    s << "DragFlight::state: t = " << t << " outside the flight [" << t0_ << ", " << endTime() << "]";
    throw InvalidInput(s.str());
  }
  const double c = std::clamp(tau, 0.0, duration_);
  const auto i = std::min(static_cast<std::size_t>(c / step_), knots_.size() - 1);
  const double rest = c - static_cast<double>(i) * step_;
  if (rest <= 0.0) return knots_[i];
  return rk4Step(knots_[i], rest, k_, g_w_);
}

Eigen::Vector3d parabola(const FlightState& initial, double t, const Eigen::Vector3d& g_w) {
  return initial.p + t * initial.v + 0.5 * t * t * g_w;
}

Eigen::Isometry3d dartPose(const Eigen::Vector3d& position_w, const Eigen::Vector3d& velocity_w) {
  core::requireFinite(position_w, "dartPose: position");
  core::requireFinite(velocity_w, "dartPose: velocity");
  if (velocity_w.norm() < 1e-9) throw InvalidInput("dartPose: velocity is zero (direction undefined)");
  const Eigen::Vector3d z = velocity_w.normalized();
  Eigen::Vector3d x = Eigen::Vector3d::UnitZ().cross(z);
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitX();  // flying vertically
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d w_M_d = Eigen::Isometry3d::Identity();
  w_M_d.linear().col(0) = x;
  w_M_d.linear().col(1) = y;
  w_M_d.linear().col(2) = z;
  w_M_d.translation() = position_w;
  return w_M_d;
}

// ----------------------------------------------------------------------------------------------

TiltTable::TiltTable(const TiltTableParams& params, const TiltTableState& initial)
    : params_(params), state_(initial) {
  core::requirePositive(params.side, "TiltTableParams.side");
  core::requirePositive(params.ball_radius, "TiltTableParams.ball_radius");
  if (params.ball_radius >= 0.5 * params.side) {
    throw InvalidInput("TiltTableParams.ball_radius must be smaller than side/2");
  }
  core::requirePositive(params.max_angle, "TiltTableParams.max_angle");
  core::requirePositive(params.max_rate, "TiltTableParams.max_rate");
  requireNonNegative(params.delay, "TiltTableParams.delay");
  core::requirePositive(params.substep, "TiltTableParams.substep");
  core::requirePositive(params.history, "TiltTableParams.history");
  core::requireFinite(initial.tilt, "TiltTable: initial tilt");
  core::requireFinite(initial.p, "TiltTable: initial ball position");
  core::requireFinite(initial.v, "TiltTable: initial ball velocity");
  core::requireFinite(initial.t, "TiltTable: initial time");
  const double lim = limit();
  state_.p = state_.p.cwiseMax(-lim).cwiseMin(lim);
  state_.tilt = state_.tilt.cwiseMax(-params.max_angle).cwiseMin(params.max_angle);
  target_ = state_.tilt;
  history_.push_back(state_);
}

void TiltTable::command(double t, const Eigen::Vector2d& tilt) {
  core::requireFinite(t, "TiltTable::command: t");
  core::requireFinite(tilt, "TiltTable::command: tilt");
  if (t < last_command_time_) throw InvalidInput("TiltTable::command: time goes backwards");
  last_command_time_ = t;
  commands_.emplace_back(t, tilt);
}

void TiltTable::push(const Eigen::Vector2d& dv) {
  core::requireFinite(dv, "TiltTable::push: dv");
  state_.v += dv;
}

Eigen::Isometry3d TiltTable::tablePose(const Eigen::Vector2d& tilt) const {
  Eigen::Isometry3d b_M_t = Eigen::Isometry3d::Identity();
  b_M_t.linear() = core::rotation(Eigen::Vector3d::UnitX(), tilt.x()) *
                   core::rotation(Eigen::Vector3d::UnitY(), tilt.y());
  return params_.w_M_base * b_M_t;
}

Eigen::Vector2d TiltTable::rollingAcceleration(const Eigen::Vector2d& tilt) const {
  const Eigen::Vector3d g_t = tablePose(tilt).linear().transpose() * gravityWorld();
  return (5.0 / 7.0) * g_t.head<2>();
}

void TiltTable::step(double dt) {
  const double t_new = state_.t + dt;
  // Actuator: the latest command issued at least `delay` before the start of the sub-step.
  while (!commands_.empty() && commands_.front().first + params_.delay <= state_.t + 1e-12) {
    target_ = commands_.front().second;
    commands_.pop_front();
  }
  const Eigen::Vector2d clamped = target_.cwiseMax(-params_.max_angle).cwiseMin(params_.max_angle);
  const Eigen::Vector2d delta = (clamped - state_.tilt).cwiseMax(-params_.max_rate * dt).cwiseMin(params_.max_rate * dt);
  const Eigen::Vector2d tilt_mid = state_.tilt + 0.5 * delta;
  // Ball: constant acceleration over the sub-step (evaluated at the mid tilt), exact integration.
  const Eigen::Vector2d a = rollingAcceleration(tilt_mid);
  state_.p += state_.v * dt + 0.5 * a * dt * dt;
  state_.v += a * dt;
  state_.tilt += delta;
  state_.t = t_new;
  // Inelastic borders.
  const double lim = limit();
  for (int i = 0; i < 2; ++i) {
    if (state_.p[i] > lim) {
      state_.p[i] = lim;
      state_.v[i] = std::min(state_.v[i], 0.0);
    } else if (state_.p[i] < -lim) {
      state_.p[i] = -lim;
      state_.v[i] = std::max(state_.v[i], 0.0);
    }
  }
}

void TiltTable::advanceTo(double t) {
  core::requireFinite(t, "TiltTable::advanceTo: t");
  if (t < state_.t - 1e-12) throw InvalidInput("TiltTable::advanceTo: time goes backwards");
  while (state_.t < t - 1e-12) {
    step(std::min(params_.substep, t - state_.t));
    history_.push_back(state_);
  }
  while (history_.size() > 2 && history_.front().t < state_.t - params_.history) history_.pop_front();
}

TiltTableState TiltTable::stateAt(double t) const {
  if (t >= history_.back().t) return history_.back();
  if (t <= history_.front().t) return history_.front();
  const auto it = std::lower_bound(history_.begin(), history_.end(), t,
                                   [](const TiltTableState& s, double tt) { return s.t < tt; });
  const TiltTableState& b = *it;
  const TiltTableState& a = *(it - 1);
  const double w = (t - a.t) / std::max(b.t - a.t, 1e-15);
  TiltTableState s;
  s.t = t;
  s.tilt = a.tilt + w * (b.tilt - a.tilt);
  s.p = a.p + w * (b.p - a.p);
  s.v = a.v + w * (b.v - a.v);
  return s;
}

// ----------------------------------------------------------------------------------------------

namespace {
// The turn at v of the polyline a → v → b: φ in [0, π] and the sign of the cross product (+1 left).
std::pair<double, double> turnAt(const Eigen::Vector2d& a, const Eigen::Vector2d& v, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d_in = (v - a).normalized(), d_out = (b - v).normalized();
  const double cross = d_in.x() * d_out.y() - d_in.y() * d_out.x();
  return {std::atan2(std::abs(cross), d_in.dot(d_out)), cross >= 0.0 ? 1.0 : -1.0};
}
}  // namespace

ScreenPath::ScreenPath(const ScreenPathParams& params, core::Rng& rng) : params_(params) {
  core::requirePositive(params.speed, "ScreenPathParams.speed");
  core::requireFinite(params.center, "ScreenPathParams.center");
  if (!(params.corner_radius >= 0.0) || !std::isfinite(params.corner_radius))
    throw core::InvalidInput("ScreenPathParams.corner_radius must be >= 0");
  if (params.corner_radius > 0.0 && params.shape != PathShape::Random)
    throw core::InvalidInput("ScreenPathParams.corner_radius is for the random path");
  const Eigen::Vector2d c = params.center;
  switch (params.shape) {
    case PathShape::Rectangle: {
      core::requirePositive(params.width, "ScreenPathParams.width");
      core::requirePositive(params.height, "ScreenPathParams.height");
      const double hw = 0.5 * params.width, hh = 0.5 * params.height;
      // Screen frame: x right, y down; clockwise on screen: TL -> TR -> BR -> BL -> TL.
      vertices_ = {c + Eigen::Vector2d(-hw, -hh), c + Eigen::Vector2d(hw, -hh), c + Eigen::Vector2d(hw, hh),
                   c + Eigen::Vector2d(-hw, hh), c + Eigen::Vector2d(-hw, -hh)};
      break;
    }
    case PathShape::Circle:
      core::requirePositive(params.radius, "ScreenPathParams.radius");
      break;
    case PathShape::Random: {
      core::requirePositive(params.width, "ScreenPathParams.width");
      core::requirePositive(params.height, "ScreenPathParams.height");
      core::requirePositive(params.duration, "ScreenPathParams.duration");
      const double needed = params.speed * params.duration;
      const double hw = 0.5 * params.width, hh = 0.5 * params.height;
      vertices_.push_back(c);
      double length = 0.0;
      const double r = params.corner_radius;
      // Segments of at least 2r when rounded: then any turn up to 90° fits (r tan 45° = r).
      const double min_segment = std::max(0.1 * std::min(params.width, params.height), 2.0 * r);
      // A rounded corner at the last vertex v needs its tangent length r tan(φ/2) within half of both
      // segments at v: waypoints that would need a smaller radius are drawn again (after 1000 misses, the
      // last waypoint itself is drawn again).
      const auto fits = [&](const Eigen::Vector2d& next) {
        if (r <= 0.0 || vertices_.size() < 2) return true;
        const Eigen::Vector2d a = vertices_[vertices_.size() - 2], v = vertices_.back();
        const double phi = turnAt(a, v, next).first;
        const double L = r * std::tan(0.5 * std::min(phi, 3.1));
        return L <= 0.5 * (v - a).norm() && L <= 0.5 * (next - v).norm();
      };
      const auto addWaypoint = [&]() {
        Eigen::Vector2d next;
        int tries = 0;
        do {  // avoid degenerate (very short) segments
          next = c + Eigen::Vector2d(core::uniform(rng, -hw, hw), core::uniform(rng, -hh, hh));
          if (r > 0.0 && !fits(next) && ++tries >= 1000 && vertices_.size() > 2) {
            // No turn from here fits (e.g. heading into a corner of the box): draw the last waypoint again.
            length -= (vertices_.back() - vertices_[vertices_.size() - 2]).norm();
            vertices_.pop_back();
            return;
          }
        } while ((next - vertices_.back()).norm() < min_segment || !fits(next));
        length += (next - vertices_.back()).norm();
        vertices_.push_back(next);
      };
      while (length <= needed) addWaypoint();
      if (params.corner_radius > 0.0) {  // the arcs cut the corners: draw on until the rounded path is long enough
        roundCorners();
        while (pieces_.back().s0 + pieces_.back().length <= needed) {
          addWaypoint();
          roundCorners();
        }
      }
      break;
    }
  }
  cumulative_.assign(vertices_.size(), 0.0);
  for (std::size_t i = 1; i < vertices_.size(); ++i) {
    cumulative_[i] = cumulative_[i - 1] + (vertices_[i] - vertices_[i - 1]).norm();
  }
}

void ScreenPath::roundCorners() {
  pieces_.clear();
  {  // Fillets: at vertex V with unit directions d_in, d_out and turn φ, the arc of radius r touches the
    // segments at V − L d_in and V + L d_out, L = r tan(φ/2) (L at most half of either segment; r reduced to
    // match), centre T_in + r n, n the normal of d_in towards the turn; it sweeps φ.
    double s = 0.0;
    Eigen::Vector2d from = vertices_.front();
    const auto addLine = [&](const Eigen::Vector2d& to) {
      Piece p;
      p.s0 = s;
      p.length = (to - from).norm();
      p.p0 = from;
      p.dir = p.length > 0.0 ? Eigen::Vector2d((to - from) / p.length) : Eigen::Vector2d(1.0, 0.0);
      pieces_.push_back(p);
      s += p.length;
      from = to;
    };
    for (std::size_t i = 1; i + 1 < vertices_.size(); ++i) {
      const Eigen::Vector2d a = vertices_[i - 1], v = vertices_[i], b = vertices_[i + 1];
      const Eigen::Vector2d d_in = (v - a).normalized(), d_out = (b - v).normalized();
      const auto [phi, sign] = turnAt(a, v, b);
      if (phi < 1e-9) continue;  // straight on: no arc
      // The first tangent point must not go back past `from` (the previous arc's end).
      const double room = std::min((v - from).norm(), 0.5 * (b - v).norm());
      double L = params_.corner_radius * std::tan(0.5 * phi);
      L = std::min(L, std::min(0.5 * (v - a).norm(), room));
      const double r = L / std::tan(0.5 * phi);
      const Eigen::Vector2d t_in = v - L * d_in;
      addLine(t_in);
      Piece arc;
      arc.s0 = s;
      arc.radius = r;
      arc.sign = sign;
      arc.length = r * phi;
      arc.centre = t_in + r * sign * Eigen::Vector2d(-d_in.y(), d_in.x());
      arc.a0 = std::atan2(t_in.y() - arc.centre.y(), t_in.x() - arc.centre.x());
      pieces_.push_back(arc);
      s += arc.length;
      from = v + L * d_out;
    }
    addLine(vertices_.back());
  }
}

Eigen::Vector2d ScreenPath::atArcLength(double s) const {
  if (!pieces_.empty()) {
    s = std::clamp(s, 0.0, pieces_.back().s0 + pieces_.back().length);
    const auto it = std::upper_bound(pieces_.begin(), pieces_.end(), s, [](double v, const Piece& p) { return v < p.s0; });
    const Piece& p = *(it == pieces_.begin() ? it : it - 1);
    const double u = s - p.s0;
    if (p.radius <= 0.0) return p.p0 + u * p.dir;
    const double a = p.a0 + p.sign * u / p.radius;
    return p.centre + p.radius * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  const double total = cumulative_.back();
  if (params_.shape == PathShape::Rectangle) s = std::fmod(std::fmod(s, total) + total, total);
  s = std::clamp(s, 0.0, total);
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const std::size_t i = std::min(static_cast<std::size_t>(it - cumulative_.begin()), cumulative_.size() - 1);
  const std::size_t i0 = i == 0 ? 0 : i - 1;
  const double seg = cumulative_[i] - cumulative_[i0];
  const double w = seg > 0.0 ? (s - cumulative_[i0]) / seg : 0.0;
  return vertices_[i0] + w * (vertices_[i] - vertices_[i0]);
}

Eigen::Vector2d ScreenPath::position(double t) const {
  core::requireFinite(t, "ScreenPath::position: t");
  const double s = params_.speed * t;
  if (params_.shape == PathShape::Circle) {
    const double a = s / params_.radius;
    return params_.center + params_.radius * Eigen::Vector2d(std::cos(a), std::sin(a));
  }
  return atArcLength(s);
}

Eigen::Vector2d ScreenPath::velocity(double t) const {
  core::requireFinite(t, "ScreenPath::velocity: t");
  if (params_.shape == PathShape::Circle) {
    const double a = params_.speed * t / params_.radius;
    return params_.speed * Eigen::Vector2d(-std::sin(a), std::cos(a));
  }
  const double h = 1e-6;
  const Eigen::Vector2d d = atArcLength(params_.speed * t + h) - atArcLength(params_.speed * t);
  return d.norm() > 0.0 ? Eigen::Vector2d(params_.speed * d.normalized()) : Eigen::Vector2d::Zero();
}

std::vector<double> ScreenPath::cornerTimes(double t_end) const {
  std::vector<double> out;
  if (!pieces_.empty()) {
    for (const Piece& p : pieces_) {
      const double t = (p.s0 + 0.5 * p.length) / params_.speed;
      if (p.radius > 0.0 && t > 0.0 && t <= t_end) out.push_back(t);
    }
    return out;
  }
  if (params_.shape == PathShape::Circle || cumulative_.size() < 3) return out;
  const double total = cumulative_.back();
  const bool closed = params_.shape == PathShape::Rectangle;
  const double s_end = params_.speed * t_end;
  for (double lap = 0.0; lap <= s_end; lap += total) {
    // Interior vertices of the open polyline; every vertex of the closed one (its start included after lap 0).
    for (std::size_t i = 1; i < cumulative_.size(); ++i) {
      if (!closed && i + 1 == cumulative_.size()) break;
      const double s = lap + cumulative_[i];
      if (s > 0.0 && s <= s_end) out.push_back(s / params_.speed);
    }
    if (!closed) break;
  }
  return out;
}

// ----------------------------------------------------------------------------------------------

Eigen::Vector2d GroundTarget::nominal(GroundProfile profile, double k) {
  switch (profile) {
    case GroundProfile::Capture:
      return {0.30 * (std::cos(0.01 * k) + 1.0), 0.7 * std::sin(0.03 * k + core::kPi / 1.5)};
    case GroundProfile::FilterTest:
      return {0.15 * (std::sin(0.02 * k) + 1.0), 0.7 * std::cos(0.01 * k)};
  }
  return {0.0, 0.0};
}

namespace {
// Exact unicycle motion over dt with constant (v, ω).
GroundState unicycle(const GroundState& s, double dt) {
  GroundState n = s;
  if (std::abs(s.omega) < 1e-9) {
    n.x += s.v * dt * std::cos(s.theta);
    n.y += s.v * dt * std::sin(s.theta);
  } else {
    n.x += s.v / s.omega * (std::sin(s.theta + s.omega * dt) - std::sin(s.theta));
    n.y += s.v / s.omega * (std::cos(s.theta) - std::cos(s.theta + s.omega * dt));
  }
  n.theta += s.omega * dt;
  return n;
}
}  // namespace

GroundTarget::GroundTarget(const GroundTargetParams& params, core::Rng& rng) : params_(params) {
  core::requirePositive(params.profile_period, "GroundTargetParams.profile_period");
  core::requirePositive(params.duration, "GroundTargetParams.duration");
  core::requirePositive(params.substep, "GroundTargetParams.substep");
  core::requireFinite(params.start, "GroundTargetParams.start");
  core::requireFinite(params.heading, "GroundTargetParams.heading");
  // ξ variances of [K] in cm²/s² (v) and rad²/s² (ω), converted to SI standard deviations.
  const bool capture = params.profile == GroundProfile::Capture;
  const double sd_v = std::sqrt(capture ? 2.0 : 3.0) * 0.01;
  const double sd_w = std::sqrt(0.1);
  const auto n_inputs = static_cast<std::size_t>(std::ceil(params.duration / params.profile_period)) + 2;
  inputs_.reserve(n_inputs);
  for (std::size_t k = 0; k < n_inputs; ++k) {
    Eigen::Vector2d u = nominal(params.profile, static_cast<double>(k));
    if (params.noise) {
      u.x() += core::gaussian(rng, sd_v);
      u.y() += core::gaussian(rng, sd_w);
    }
    u.x() = std::max(u.x(), 0.0);  // the toy does not drive backwards
    inputs_.push_back(u);
  }
  GroundState s;
  s.x = params.start.x();
  s.y = params.start.y();
  s.theta = params.heading;
  const auto n = static_cast<std::size_t>(std::ceil(params.duration / params.substep)) + 1;
  knots_.reserve(n + 1);
  for (std::size_t i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) * params.substep;
    const auto k = std::min(static_cast<std::size_t>(t / params.profile_period + 1e-9), inputs_.size() - 1);
    s.v = inputs_[k].x();
    s.omega = inputs_[k].y();
    knots_.push_back(s);
    s = unicycle(s, params.substep);
  }
}

GroundState GroundTarget::state(double t) const {
  core::requireFinite(t, "GroundTarget::state: t");
  if (t < -1e-12 || t > params_.duration + 1e-12) {
    std::ostringstream s;
    s << "GroundTarget::state: t = " << t << " outside [0, " << params_.duration << "]";
    throw InvalidInput(s.str());
  }
  const double c = std::clamp(t, 0.0, params_.duration);
  const auto i = std::min(static_cast<std::size_t>(c / params_.substep), knots_.size() - 1);
  const double rest = c - static_cast<double>(i) * params_.substep;
  return rest > 0.0 ? unicycle(knots_[i], rest) : knots_[i];
}

}  // namespace viewline::sim
