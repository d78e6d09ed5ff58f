#pragma once
// Perception quality of a camera pose as Fisher information (paper Sec. V-D, eqs. 5-6, after
// Zhang & Scaramuzza 2020): the camera is a bearing sensor, each landmark l observed from the
// camera pose x adds FIM(l; x) = J^T J / sigma^2 with J the Jacobian of the unit bearing.
//
// Perturbation: the camera pose X_WC is perturbed on the left in the world frame,
// X_WC <- Exp(xi) X_WC with xi = (dp, dtheta). Then J = P(l^C) R_CW [-I3  [l^W]x], where
// P(v) = I/|v| - v v^T/|v|^3. Eq. 6 prints [I3 [l^W]x] without R_CW: R_CW only rotates rows
// (P(R v) R = R P(v)), and the sign of the translation block is the convention of dp; neither
// changes the determinant, which is all the planner uses.
//
// The information is summed in the camera-centred frame (world-aligned axes, origin at the
// camera position). Moving the origin is a unimodular congruence of the FIM (det unchanged),
// and in that frame each landmark's block has a closed form in its unit direction u and
// distance d: (1/sigma^2) [[(I-uu^T)/d^2, -[u]x/d], [[u]x/d, I-uu^T]]. It does not depend on the
// camera's rotation; yaw enters only through which landmarks are in the field of view.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace tgnav::planner {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix36d = Eigen::Matrix<double, 3, 6>;

// Eq. 6 (with R_CW, see above): d bearing_C / d xi.
Matrix36d bearingJacobian(const Eigen::Isometry3d& X_WC, const Eigen::Vector3d& l_W);
// Eq. 5: J^T J / sigma^2, in the world frame of the perturbation above.
Matrix6d landmarkInformation(const Eigen::Isometry3d& X_WC, const Eigen::Vector3d& l_W, double sigma_rad);

// Information of a landmark seen from camera position p_W, `weight` landmarks at the same point,
// in the camera-centred frame (same determinant as the sum of landmarkInformation()).
void addCentredInformation(const Eigen::Vector3d& p_W, const Eigen::Vector3d& l_W, double weight, double sigma_rad,
                           Matrix6d* info);

// log det(I + epsilon * Id): the regularised perception score of one pose (eq. 8's summand).
// A bearing FIM has rank 2 per landmark, so with fewer than three well-spread landmarks det I = 0;
// epsilon floors the score at 6 log(epsilon) (no landmark) and keeps it finite and monotone.
double logDetInformation(const Matrix6d& info, double epsilon);

}  // namespace tgnav::planner
