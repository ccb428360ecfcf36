#pragma once
// Ballistic flight with quadratic air drag (EKF/UKF model; beyond [L]: real
// balls and darts have drag).
//
// State (n = 6): x = (p, ṗ) = (p, v)  [m, m/s], world frame.
// Continuous model:
//
//   ṗ = v,   v̇ = g_vec − k |v| v + w,      g_vec = −g·up,  k = ρ Cd A / (2 m)  [1/m]
//
// w white acceleration noise of spectral density q [m²/s³] per axis.
// Over a step dt the mean is integrated with classical RK4 on `substeps` equal
// sub-steps. The Jacobian F = ∂x(t+dt)/∂x(t) is analytic: RK4 applied to the
// variational equation Ṡ = J(x) S, S(0) = I, with the same stages, which is
// exactly the derivative of the RK4 map (differentiation commutes with the
// Runge-Kutta stages). The continuous Jacobian is
//
//   J = [ 0  I                          ]
//       [ 0  −k (|v| I + v vᵀ / |v|)    ]   (the lower-right block is 0 at v = 0).
//
// Process noise of the step: Van Loan (discretize) of the model linearised at
// the given point, Q = ∫₀^dt e^{Js} G q Gᵀ e^{Jᵀs} ds, G = [0; I].

#include <Eigen/Core>

#include "viewline/estimation/nonlinear.h"

namespace viewline::estimation {

/// Ballistic flight with quadratic air drag in the world frame: state (p, v) [m, m/s], RK4 mean, analytic Jacobian.
struct DragBallisticModel {
  Eigen::Vector3d up = Eigen::Vector3d::UnitZ();  ///< world up axis (non-zero)
  double g = 9.81;                                 ///< gravity [m/s²], >= 0
  double k = 0.0;                                  ///< drag constant ρ Cd A / (2m) [1/m], >= 0
  double q = 1.0;                                  ///< acceleration noise spectral density [m²/s³], >= 0
  int substeps = 4;                                ///< RK4 sub-steps per transition, >= 1

  /// State dimension n = 6.
  static constexpr Eigen::Index kStateDim = 6;

  /// k = ρ Cd A / (2 m): air density ρ [kg/m³], drag coefficient Cd [-], cross-section A [m²],
  /// mass m [kg]; all finite, ρ, Cd, A >= 0, m > 0.
  static double dragConstant(double rho, double cd, double area, double mass);

  /// Gravity vector −g·up/|up| [m/s²].
  Eigen::Vector3d gravity() const;
  /// Continuous dynamics ẋ = f_c(x) (noise-free).
  Eigen::Matrix<double, 6, 1> derivative(const Eigen::Matrix<double, 6, 1>& x) const;
  /// Continuous Jacobian J = ∂f_c/∂x.
  Eigen::Matrix<double, 6, 6> derivativeJacobian(const Eigen::Matrix<double, 6, 1>& x) const;
  /// Mean propagation over dt (> 0) by RK4 with `substeps` sub-steps.
  Eigen::VectorXd propagate(const Eigen::VectorXd& x, double dt) const;
  /// ∂propagate(x, dt)/∂x (analytic, variational equations).
  Eigen::MatrixXd jacobian(const Eigen::VectorXd& x, double dt) const;
  /// Process noise of a step of dt linearised at x.
  Eigen::MatrixXd processNoise(const Eigen::VectorXd& x, double dt) const;
  /// propagate() on a fixed-size state: the same arithmetic and checks, no heap allocation (the
  /// planner's crossing search calls it a hundred times per update).
  Eigen::Matrix<double, 6, 1> propagateFixed(const Eigen::Matrix<double, 6, 1>& x, double dt) const;
  /// jacobian() on a fixed-size state: the same arithmetic and checks, no heap allocation.
  Eigen::Matrix<double, 6, 6> jacobianFixed(const Eigen::Matrix<double, 6, 1>& x, double dt) const;
  /// propagateFixed(x, dt), and its Jacobian jacobianFixed(x, dt) into S, in one pass (the same
  /// bits as the two calls: the variational equations already carry the mean).
  Eigen::Matrix<double, 6, 1> propagateWithJacobianFixed(const Eigen::Matrix<double, 6, 1>& x, double dt,
                                                         Eigen::Matrix<double, 6, 6>& S) const;
  /// processNoise() on fixed-size matrices (Van Loan on a 12x12 matrix exponential, m², m²/s, m²/s²):
  /// the same arithmetic, no heap allocation (the planner's crossing covariance on every update).
  Eigen::Matrix<double, 6, 6> processNoiseFixed(const Eigen::Matrix<double, 6, 1>& x, double dt) const;
  /// f, F and Q (Q linearised at x_lin, normally the current estimate) for dt > 0.
  NonlinearTransition transition(double dt, const Eigen::VectorXd& x_lin) const;
  /// Throws core::InvalidInput naming the field (up, g, k, q, substeps).
  void validate() const;
};

}  // namespace viewline::estimation
