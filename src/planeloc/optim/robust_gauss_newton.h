// Robust Gauss-Newton over a small fixed-size parameter: normal equations of whitened scalar
// residuals with Huber weights (iteratively reweighted least squares), plus a Gaussian prior on
// the parameter. The caller owns the parametrization: it linearizes at its current estimate
// (re-associating its data if it wants) and applies each step on its own manifold.
//
// For a problem of a few hundred to a few thousand residuals and N <= 6 unknowns this is what
// Ceres would do with a HuberLoss, without building a Problem: the normal equations are
// accumulated directly, and the order of the floating-point operations is the caller's.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

namespace planeloc {

// The Huber-weighted normal equations J^T W J x = -J^T W r of one linearization.
template <int N>
class HuberNormalEquations {
 public:
  using Vector = Eigen::Matrix<double, N, 1>;
  using Row = Eigen::Matrix<double, 1, N>;
  using Matrix = Eigen::Matrix<double, N, N>;

  // `huber_threshold`: the whitened residual (in sigmas) beyond which the weight is
  // threshold / |r| instead of 1 (the loss grows linearly there); +inf gives least squares.
  explicit HuberNormalEquations(double huber_threshold) : huber_threshold_(huber_threshold) {}

  // Adds one residual divided by its sigma and the Jacobian row of that whitened residual.
  void Add(double whitened_residual, const Row& whitened_jacobian) {
    const double weight = std::abs(whitened_residual) <= huber_threshold_
                              ? 1.0
                              : huber_threshold_ / std::abs(whitened_residual);
    hessian_ += weight * whitened_jacobian.transpose() * whitened_jacobian;
    gradient_ += weight * whitened_jacobian.transpose() * whitened_residual;
  }

  // The Gauss-Newton step with a Gaussian prior of information `prior_information` (zero: none)
  // on a parameter that is `deviation` away from the prior's mean: the minimizer of
  // |J x + r|_W^2 + (deviation + x)^T P (deviation + x). Non-finite when the system is singular.
  Vector Step(const Matrix& prior_information, const Vector& deviation) const {
    return -(hessian_ + prior_information).ldlt().solve(gradient_ + prior_information * deviation);
  }

  const Matrix& hessian() const { return hessian_; }    // J^T W J
  const Vector& gradient() const { return gradient_; }  // J^T W r

 private:
  double huber_threshold_;
  Matrix hessian_ = Matrix::Zero();
  Vector gradient_ = Vector::Zero();
};

// Runs `iterations` robust Gauss-Newton steps. Iteration k calls
// `linearize(k, equations)`, which adds the whitened residuals at the current estimate to fresh
// (zero) equations and returns the estimate's deviation from the prior's mean (a Vector); the step
// is then solved and handed to `apply(step)`, which updates the estimate. A non-finite step (a
// singular system) ends the iteration without being applied. Returns the number of steps applied.
template <int N, typename Linearize, typename Apply>
int RobustGaussNewton(int iterations, double huber_threshold,
                      const typename HuberNormalEquations<N>::Matrix& prior_information,
                      Linearize&& linearize, Apply&& apply) {
  int applied = 0;
  for (int k = 0; k < iterations; ++k) {
    HuberNormalEquations<N> equations(huber_threshold);
    const typename HuberNormalEquations<N>::Vector deviation = linearize(k, equations);
    const typename HuberNormalEquations<N>::Vector step =
        equations.Step(prior_information, deviation);
    if (!step.allFinite()) break;
    apply(step);
    ++applied;
  }
  return applied;
}

}  // namespace planeloc
