#pragma once
// The adjugate of a 3x3 matrix, by cofactors: A^-1 = adj(A) / det(A). The step's bordered
// Newton systems (step_solver.cc), its first guess (step_equations.h, SecularGuess) and its
// sensitivities (estimator/step_sensitivity.cc) solve with it, so that one division by
// det A, off the chain of dependent operations, replaces a pivoted LU (docs/performance.md,
// "The general step").

#include <Eigen/Core>

namespace slideid {

/// adj(A): adj(A)_ij is the cofactor of A_ji.
inline Eigen::Matrix3d Adjugate3(const Eigen::Matrix3d& A) {
  Eigen::Matrix3d adj;
  adj(0, 0) = A(1, 1) * A(2, 2) - A(1, 2) * A(2, 1);
  adj(1, 0) = A(1, 2) * A(2, 0) - A(1, 0) * A(2, 2);
  adj(2, 0) = A(1, 0) * A(2, 1) - A(1, 1) * A(2, 0);
  adj(0, 1) = A(0, 2) * A(2, 1) - A(0, 1) * A(2, 2);
  adj(1, 1) = A(0, 0) * A(2, 2) - A(0, 2) * A(2, 0);
  adj(2, 1) = A(0, 1) * A(2, 0) - A(0, 0) * A(2, 1);
  adj(0, 2) = A(0, 1) * A(1, 2) - A(0, 2) * A(1, 1);
  adj(1, 2) = A(0, 2) * A(1, 0) - A(0, 0) * A(1, 2);
  adj(2, 2) = A(0, 0) * A(1, 1) - A(0, 1) * A(1, 0);
  return adj;
}

/// det(A), expanded along A's first row with the cofactors in `adj` (Adjugate3(A)).
inline double Determinant3(const Eigen::Matrix3d& A, const Eigen::Matrix3d& adj) {
  return A(0, 0) * adj(0, 0) + A(0, 1) * adj(1, 0) + A(0, 2) * adj(2, 0);
}

}  // namespace slideid
