#pragma once
// Ball-on-table balancing controller ([M]'s closed loop, SPEC §3): a discrete LQR on the
// estimated ball state, with the table's tilt *rate* as the input so that the wrist's angle and
// rate limits become simple, exactly enforceable bounds.
//
// Plant, per table axis i ∈ {x, y} (small angles; a solid ball rolling without slipping):
//   ė_i = v_i,   v̇_i = c φ_i,   φ̇_i = u_i(t − D),      c = (5/7) g,  e_i = p_i − p_ref,i
// where φ is the "axis tilt" that accelerates the ball along +i. With the table frame
// w_M_table = Rx(θx) · Ry(θy) (robots::TableTilt), a_x = c cos θx sin θy and a_y = −c sin θx, so
//   φ_x = θy,   φ_y = −θx     (commanded tilt = (θx, θy) = (−φ_y, φ_x)).
// D = latency + actuator delay is the time from the estimate's instant to the start of the
// tilt motion it causes. The input u_k is a tilt rate held over one period T (the frame
// period); the wrist follows the resulting ramp because the loop sends it interpolated
// position commands φ_k + u_k (t − t_k) (commandAt), which never exceed the rate limit.
//
// Exact ZOH discretisation with the fractional delay D = m T + τ (0 <= τ < T):
//   s(k+1) = Φ(T) s(k) + e^{A (T−τ)} Γ(τ) u(k−m−1) + Γ(T−τ) u(k−m),   s = (e, v, φ),
//   Γ(h) = ∫₀ʰ e^{A s} ds B        (estimation::discretize, Van Loan)
// augmented with the m + 1 inputs in flight and an integral of the position error
//   ι(k+1) = ι(k) + T e(k)   (conditional integration: frozen while |e| > integral_band or
//   while the input saturates — anti-windup).
// State z = (e, v, φ, ι, u(k−1), …, u(k−m−1)). The gain is the LQR of this model:
//   X = Aᵀ X A + Q − Aᵀ X B (Bᵀ X B + R)⁻¹ Bᵀ X A,   K = (Bᵀ X B + R)⁻¹ Bᵀ X A,  u = −K z,
// X from estimation::solveDare on the dual pair (Aᵀ, Bᵀ). Q = diag(q_position, q_velocity,
// q_tilt, q_integral, 0…), R = r_rate.
//
// Limits (never exceeded, tested): u is clipped to ±max_rate and to the range that keeps the
// ramp's end inside ±max_angle: |φ_k + T u_k| <= max_angle. The internal tilt φ and the
// inputs in flight are propagated with the *applied* (clipped) inputs, so the model stays
// true after saturation.
//
// A wrist that does not take commands (it stops answering, or refuses them with a limit error)
// holds its last accepted tilt: hold() puts that tilt into the model in place of what the
// refused ramps would have done, so the next ramp starts from where the wrist is, and the
// integral does not grow on an error the controller cannot act on.

#include <Eigen/Core>

namespace viewline::control {

/// Configuration of the LQR table balancer (periods in s, angles in rad, LQR weights).
struct TableBalancerConfig {
  double period = 0.02;        ///< T, controller period = frame period, s (> 0)
  double delay = 0.02;         ///< D = latency + actuator delay, s (>= 0)
  double max_angle = 0.35;     ///< |θ| limit per axis, rad (> 0)
  double max_rate = 1.5;       ///< |θ̇| limit per axis, rad/s (> 0)
  double gravity = 9.81;       ///< m/s²
  double q_position = 400.0;   ///< LQR weight on e², 1/m²
  double q_velocity = 10.0;    ///< on v², s²/m²
  double q_tilt = 1.0;         ///< on φ², 1/rad²
  double q_integral = 0.0;     ///< on ι², 1/(m² s²); 0 = no integral action
  double r_rate = 0.05;        ///< on u², s²/rad²
  double integral_band = 0.02; ///< integrate only while |e| < this, m

  void validate() const;  ///< throws core::InvalidInput naming the field
};

/// The commanded tilt ramp of one period: θ(t) = start + rate (t − t0) for t in [t0, t0 + T].
struct TiltRamp {
  double t0 = 0.0;  ///< start time of the ramp, s
  Eigen::Vector2d start = Eigen::Vector2d::Zero();  ///< (θx, θy) at t0, rad
  Eigen::Vector2d rate = Eigen::Vector2d::Zero();   ///< (θ̇x, θ̇y), rad/s
  double period = 0.02;  ///< ramp duration T, s
  /// Position command at t (held at the ramp's end after t0 + T, at its start before t0).
  Eigen::Vector2d commandAt(double t) const;
  /// Commanded tilt (θx, θy) at the ramp's end t0 + T, rad.
  Eigen::Vector2d end() const { return start + period * rate; }
};

/// LQR balancer of a ball on a tilting table with delayed, rate-limited tilt commands ([M]'s closed loop).
class TableBalancer {
public:
  /// Builds the augmented model and solves the LQR; throws core::InvalidInput for a bad config.
  explicit TableBalancer(const TableBalancerConfig& config);

  /// One control step at the estimate's instant t (s): ball position p and velocity v on the
  /// table (m, m/s, table frame) and the set point (m). Returns the tilt ramp to send from t.
  TiltRamp update(double t, const Eigen::Vector2d& p, const Eigen::Vector2d& v, const Eigen::Vector2d& setpoint);

  /// Forget the integral and the inputs in flight; the table is at rest at `tilt` (θx, θy).
  void reset(const Eigen::Vector2d& tilt = Eigen::Vector2d::Zero());

  /// The wrist did not take the ramps since the last accepted command and holds `tilt` (θx, θy),
  /// rad: the model's tilt and commanded tilt become `tilt`, the inputs in flight zero; the
  /// integral is kept as it is (frozen while the loop does not call update()).
  void hold(const Eigen::Vector2d& tilt);

  /// Augmented per-axis model (z as in the file comment) and the LQR gain (1 x nz).
  const Eigen::MatrixXd& A() const { return A_; }
  /// Input matrix of the augmented per-axis model (nz x 1).
  const Eigen::MatrixXd& B() const { return B_; }
  /// LQR gain K (1 x nz), u = −K z.
  const Eigen::RowVectorXd& gain() const { return K_; }
  /// Spectral radius of A − B K (< 1 for a stabilising gain).
  double closedLoopSpectralRadius() const;
  /// The configuration in use.
  const TableBalancerConfig& config() const { return config_; }
  /// Commanded tilt (θx, θy) at the end of the last ramp.
  Eigen::Vector2d commandedTilt() const;
  /// The model's actual tilt (θx, θy) at the last update instant (commands delayed by D).
  Eigen::Vector2d modelTilt() const;

private:
  TableBalancerConfig config_;
  int m_ = 0;          ///< whole periods of delay
  Eigen::Index nz_ = 0;
  Eigen::MatrixXd A_, B_;
  Eigen::RowVectorXd K_;
  Eigen::Matrix<double, Eigen::Dynamic, 2> z_;  ///< per-axis augmented states (columns: axis x, y)
  Eigen::Vector2d phi_cmd_ = Eigen::Vector2d::Zero();  ///< commanded axis tilt at the end of the last ramp
};

}  // namespace viewline::control
