#include "planeloc/prior/lock_fusion.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace planeloc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Added to a covariance's diagonal before inverting it: a DoF declared exact (sigma 0) becomes a
// very stiff one instead of a singular matrix.
constexpr double kExactVariance = 1e-10;

Matrix6d BlockDiagonal(const Eigen::Matrix3d& a) {
  Matrix6d b = Matrix6d::Zero();
  b.topLeftCorner<3, 3>() = a;
  b.bottomRightCorner<3, 3>() = a;
  return b;
}

}  // namespace

Matrix6d PriorCovarianceAtCamera(const RegistrationPrior& prior,
                                 const Eigen::Vector3d& camera_in_world,
                                 const Eigen::Matrix3d& vehicle_axes) {
  // A change (d_shift, d_omega) of the correction about the pivot moves the camera by
  // d_shift + d_omega x (camera - pivot).
  Matrix6d to_camera = Matrix6d::Identity();
  to_camera.topRightCorner<3, 3>() = -Hat(camera_in_world - prior.pivot_in_world);
  const Matrix6d axes = BlockDiagonal(vehicle_axes);
  return axes * to_camera * prior.covariance * to_camera.transpose() * axes.transpose();
}

namespace {

// Steps 1 and 2 for the DoF in `observed` (the others, `held`, keep the current estimate): the
// registration's estimate of the observed DoF, its marginal covariance, and the mean of it and
// the current estimate (zero) weighted by their covariances.
struct Restricted {
  Eigen::VectorXd estimate, applied;
  Eigen::MatrixXd registration_covariance, current_covariance;
};

Restricted RestrictAndFuse(const Matrix6d& information, const Vector6d& z,
                           const Matrix6d& current_covariance, const Matrix6d& current_information,
                           const std::vector<int>& observed, const std::vector<int>& held) {
  Restricted out;
  // The registration's own estimate of the observed DoF, whatever the held ones are: its
  // marginal. (Conditioning it on the held DoF staying put would feed the held part of `z`, which
  // the search prior and not the planes set, through the coupling into the observed ones: on the
  // tiny street it turned a 2.8 deg heading correction into 2.0 deg.) A held DoF is as uncertain
  // to the registration as to the current estimate, at least.
  Matrix6d registration_information = information;
  registration_information(held, held) += current_information(held, held);
  const Matrix6d registration_covariance =
      registration_information.ldlt().solve(Matrix6d::Identity());
  out.estimate = z(observed);
  out.registration_covariance = registration_covariance(observed, observed);
  out.current_covariance = current_covariance(observed, observed);
  const Eigen::MatrixXd sum = out.registration_covariance + out.current_covariance;
  out.applied = out.current_covariance * sum.ldlt().solve(out.estimate);
  return out;
}

}  // namespace

FusedCorrection FuseRegistration(const RegistrationResult& result,
                                 const Matrix6d& current_covariance, double max_sigmas,
                                 double min_sigmas) {
  FusedCorrection fused;
  fused.innovation_sigma.setConstant(kInf);
  std::vector<int> observed, unobserved;
  for (int dof = 0; dof < kNumDofs; ++dof) {
    fused.registered_dofs[dof] = result.constrained[dof];
    (result.constrained[dof] ? observed : unobserved).push_back(dof);
  }
  if (observed.empty()) return fused;

  const Matrix6d& information = result.information_at_camera;
  const Vector6d& z = result.correction_at_camera;
  Matrix6d current = current_covariance;
  current.diagonal().array() += kExactVariance;
  const Matrix6d current_information = current.ldlt().solve(Matrix6d::Identity());

  const Restricted all =
      RestrictAndFuse(information, z, current, current_information, observed, unobserved);
  const Eigen::MatrixXd innovation_covariance =
      all.registration_covariance + all.current_covariance;
  fused.worst_sigmas = 0;
  std::vector<int> changed, held = unobserved;
  for (std::size_t k = 0; k < observed.size(); ++k) {
    const int dof = observed[k];
    fused.registered(dof) = all.estimate(k);
    fused.innovation_sigma(dof) = std::sqrt(std::max(0.0, innovation_covariance(k, k)));
    const double sigmas = std::abs(all.estimate(k)) / fused.innovation_sigma(dof);
    if (!(sigmas <= fused.worst_sigmas)) {
      fused.worst_sigmas = sigmas;
      fused.worst_dof = dof;
    }
    const double own_sigma = std::sqrt(std::max(0.0, all.registration_covariance(k, k)));
    (std::abs(all.estimate(k)) > min_sigmas * own_sigma ? changed : held).push_back(dof);
  }
  fused.accepted = fused.worst_sigmas <= max_sigmas;

  if (!changed.empty()) {
    std::sort(held.begin(), held.end());
    const Restricted significant =
        changed.size() == observed.size()
            ? all
            : RestrictAndFuse(information, z, current, current_information, changed, held);
    for (std::size_t k = 0; k < changed.size(); ++k) {
      fused.changed_dofs[changed[k]] = true;
      fused.applied(changed[k]) = significant.applied(k);
    }
  }

  // Covariance after the fusion: the registration's information on every observed DoF (a held
  // DoF was confirmed, not ignored).
  Matrix6d posterior_information = current_information;
  posterior_information(observed, observed) += information(observed, observed);
  const Matrix6d posterior = posterior_information.ldlt().solve(Matrix6d::Identity());
  const Eigen::Matrix3d& axes = result.vehicle_axes;
  fused.camera_position_covariance = axes.transpose() * posterior.topLeftCorner<3, 3>() * axes;

  const Eigen::Vector3d shift = axes.transpose() * fused.applied.head<3>();
  const Eigen::Matrix3d rotation = ExpSO3(axes.transpose() * fused.applied.tail<3>());
  const Eigen::Vector3d& camera = result.camera_in_world;
  fused.map_from_world = Rigid3d(rotation, camera + shift - rotation * camera);
  return fused;
}

}  // namespace planeloc
