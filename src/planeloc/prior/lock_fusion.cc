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

// Step 1 for the DoF in `observed` (the others, `held`, keep the current estimate): the
// registration's estimate of the observed DoF and its marginal covariance, and the current
// estimate's covariance of them.
struct Restricted {
  Eigen::VectorXd estimate;
  Eigen::MatrixXd registration_covariance, current_covariance;
};

Restricted Restrict(const Matrix6d& information, const Vector6d& z,
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
  return out;
}

// Positions of `dofs` within `observed` (both ascending; every element of `dofs` is observed).
std::vector<int> IndicesIn(const std::vector<int>& observed, const std::vector<int>& dofs) {
  std::vector<int> indices;
  for (const int dof : dofs) {
    indices.push_back(
        static_cast<int>(std::find(observed.begin(), observed.end(), dof) - observed.begin()));
  }
  return indices;
}

// The registration's estimate of the `changed` DoF and its covariance, conditioned on the
// `held` registered DoF being zero (Gaussian conditioning of the marginal over the observed DoF).
struct Conditional {
  Eigen::VectorXd estimate;
  Eigen::MatrixXd covariance;
};

Conditional ConditionOnHeld(const Restricted& all, const std::vector<int>& observed,
                            const std::vector<int>& changed, const std::vector<int>& held) {
  const std::vector<int> c = IndicesIn(observed, changed);
  Conditional out;
  out.estimate = all.estimate(c);
  out.covariance = all.registration_covariance(c, c);
  if (held.empty()) return out;
  const std::vector<int> h = IndicesIn(observed, held);
  const Eigen::MatrixXd cross = all.registration_covariance(c, h);
  const Eigen::LDLT<Eigen::MatrixXd> held_covariance(all.registration_covariance(h, h));
  out.estimate -= cross * held_covariance.solve(all.estimate(h));
  out.covariance -= cross * held_covariance.solve(cross.transpose());
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
      Restrict(information, z, current, current_information, observed, unobserved);
  const Eigen::MatrixXd innovation_covariance =
      all.registration_covariance + all.current_covariance;
  fused.worst_sigmas = 0;
  std::vector<int> changed, held_observed;
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
    (std::abs(all.estimate(k)) > min_sigmas * own_sigma ? changed : held_observed).push_back(dof);
  }
  fused.accepted = fused.worst_sigmas <= max_sigmas;

  // The held registered DoF stay at the current estimate, which the registration found consistent
  // with its own there; the changed ones take the registration's estimate given that, i.e. its
  // conditional mean on the held ones being zero, not its marginal. The two differ where the DoF
  // are correlated: structure 30 m behind the camera sees height and pitch only together, and on
  // tiny seed 43 the marginal changed the height by -0.089 m while the pitch that went with it
  // (0.16 deg, 1.3 of its sigma) was held, which moved that structure 9 cm off the road it lay
  // on. Holding a DoF can make another insignificant, so the test is repeated until it settles.
  while (!changed.empty()) {
    const Conditional given = ConditionOnHeld(all, observed, changed, held_observed);
    std::vector<int> still_changed;
    for (std::size_t k = 0; k < changed.size(); ++k) {
      const double own_sigma = std::sqrt(std::max(0.0, given.covariance(k, k)));
      (std::abs(given.estimate(k)) > min_sigmas * own_sigma ? still_changed : held_observed)
          .push_back(changed[k]);
    }
    if (still_changed.size() == changed.size()) {
      const Eigen::MatrixXd current_changed =
          all.current_covariance(IndicesIn(observed, changed), IndicesIn(observed, changed));
      const Eigen::VectorXd applied =
          current_changed * (current_changed + given.covariance).ldlt().solve(given.estimate);
      for (std::size_t k = 0; k < changed.size(); ++k) {
        fused.changed_dofs[changed[k]] = true;
        fused.applied(changed[k]) = applied(k);
        // The conditional estimate can exceed the marginal one; the gate holds for what is applied.
        const double sigmas = std::abs(applied(k)) / fused.innovation_sigma(changed[k]);
        if (sigmas > fused.worst_sigmas) {
          fused.worst_sigmas = sigmas;
          fused.worst_dof = changed[k];
        }
      }
      fused.accepted = fused.worst_sigmas <= max_sigmas;
      break;
    }
    changed = still_changed;
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
