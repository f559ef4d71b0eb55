// weilgen's include of Eigen's dense module. The factorisations the runtime runs on
// Eigen::MatrixXd are declared here as explicit instantiations (extern template) and compiled
// once, in uq/dense.cpp, instead of in every file that factors a matrix (a JacobiSVD or a
// SelfAdjointEigenSolver costs 4-6 s of compile time wherever it is instantiated;
// docs/performance.md, "Build time"). Only the members that do the work are listed (an
// instantiated class would compile every member). No BDCSVD: Eigen 3.4.0's reads out of bounds
// on rank-deficient input (uq/lsq.cpp).
//
// To use them, include this header instead of <Eigen/Dense> and pass the matrix to factor as
// an Eigen::MatrixXd (a product or a block is another type and is instantiated in place):
//   const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(Eigen::MatrixXd(X.transpose() * X));
#pragma once

#include <Eigen/Dense>

// X(declaration) for each instantiation: extern here, defined in dense.cpp.
#define WEILGEN_DENSE_INSTANTIATIONS(X)                                                   \
  X(void Eigen::HouseholderQR<Eigen::MatrixXd>::computeInPlace())                         \
  X(void Eigen::ColPivHouseholderQR<Eigen::MatrixXd>::computeInPlace())                   \
  X(void Eigen::PartialPivLU<Eigen::MatrixXd>::compute())                                 \
  X(Eigen::JacobiSVD<Eigen::MatrixXd>& Eigen::JacobiSVD<Eigen::MatrixXd>::compute(        \
      const Eigen::MatrixXd&, unsigned int))                                              \
  X(Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>&                                       \
        Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(         \
            const Eigen::EigenBase<Eigen::MatrixXd>&, int))                               \
  X(Eigen::LDLT<Eigen::MatrixXd>& Eigen::LDLT<Eigen::MatrixXd>::compute<Eigen::MatrixXd>( \
      const Eigen::EigenBase<Eigen::MatrixXd>&))                                          \
  X(Eigen::LLT<Eigen::MatrixXd>& Eigen::LLT<Eigen::MatrixXd>::compute<Eigen::MatrixXd>(   \
      const Eigen::EigenBase<Eigen::MatrixXd>&))

#define WEILGEN_DENSE_EXTERN(...) extern template __VA_ARGS__;
WEILGEN_DENSE_INSTANTIATIONS(WEILGEN_DENSE_EXTERN)
#undef WEILGEN_DENSE_EXTERN
