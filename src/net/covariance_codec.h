// Covariance matrices <-> the compact codes of wire_format.h: one uint8
// log-variance code per diagonal entry and one int8 partial-correlation code
// per lower-triangle entry.
//
// Decoding: variance_i = 2^(kLogVarianceMin + c_i kLogVarianceStep) and the
// partial correlations z_ij = tanh(k_ij kCorrelationStep) (|z| < 1) fill the
// rows of the lower-triangular factor W of the correlation matrix R = W W^T:
//   rem = 1; for j < i: W_ij = z_ij sqrt(rem), rem = rem (1 - z_ij^2); W_ii = sqrt(rem),
// so every row has unit norm and W_ii > 0: every code vector decodes to a
// symmetric positive-definite matrix Sigma = D R D, D = diag(sqrt(variance)),
// with exactly the decoded variances on its diagonal (the "C-vine" or
// canonical partial-correlation parametrization of correlation matrices).
//
// Encoding: variances are rounded in log2 (clamped to the smallest code; the
// caller rejects those above MaxEncodableVariance()); correlations
// rho_ij = Sigma_ij / sqrt(Sigma_ii Sigma_jj) (0 when a variance is 0,
// clamped to [-1, 1]) are turned into partial correlations row by row,
// against the already quantized rows, so that each decoded correlation is
// within half a code step of its target. An input that is not positive
// definite comes out as the positive-definite matrix whose partial
// correlations are the clamped ones.
#pragma once

#include <Eigen/Core>
#include <cstdint>

#include "swarmlio/net/wire_format.h"

namespace swarmlio::net::internal {

/// Largest variance the encoder accepts: half a code step above the top code.
double MaxEncodableVariance();
double VarianceFromCode(uint8_t code);
/// Precondition: 0 <= variance <= MaxEncodableVariance().
uint8_t VarianceCode(double variance);

/// `codes` holds CovarianceBytes(N) bytes (variances, then correlations as
/// int8 bit patterns). Preconditions: the upper triangle of `m` is finite and
/// its diagonal in [0, MaxEncodableVariance()]; the lower triangle is ignored.
template <int N>
void EncodeCovariance(const Eigen::Matrix<double, N, N>& m, uint8_t* codes);

/// False (with the offending code's index in `*bad_code`) if a correlation
/// code is -128, outside [-kCorrelationMaxCode, kCorrelationMaxCode].
template <int N>
bool DecodeCovariance(const uint8_t* codes, Eigen::Matrix<double, N, N>* m, int* bad_code);

}  // namespace swarmlio::net::internal
