// Covariance codes (math in covariance_codec.h).
#include "src/net/covariance_codec.h"

#include <algorithm>
#include <cmath>

namespace swarmlio::net::internal {
namespace {

constexpr int kMaxDimension = 6;

double CorrelationFromCode(int code) { return std::tanh(code * kCorrelationStep); }

int CorrelationCode(double z) {
  const double magnitude = std::min(std::abs(z), 1.0);
  const double steps =
      magnitude >= 1.0 ? kCorrelationMaxCode : std::atanh(magnitude) / kCorrelationStep;
  const int code = static_cast<int>(std::min<double>(std::lround(steps), kCorrelationMaxCode));
  return z < 0.0 ? -code : code;
}

/// Rows of the correlation factor W from partial correlations (decoded
/// values), shared by the encoder (as it goes) and the decoder.
class CorrelationFactor {
 public:
  void BeginRow() { remaining_ = 1.0; }
  /// Sets W_ij, the next entry of row i, from the partial correlation z.
  void Append(int i, int j, double z) {
    w_[i][j] = z * std::sqrt(remaining_);
    remaining_ *= 1.0 - z * z;
  }
  void CloseRow(int i) { w_[i][i] = std::sqrt(remaining_); }
  /// sum_k W_ik W_jk over k < j (row i partly filled, row j complete).
  double PartialDot(int i, int j) const {
    double dot = 0.0;
    for (int k = 0; k < j; ++k) dot += w_[i][k] * w_[j][k];
    return dot;
  }
  double Correlation(int i, int j) const { return PartialDot(i, j) + w_[i][j] * w_[j][j]; }
  double Diagonal(int j) const { return w_[j][j]; }
  /// 1 - sum_k W_ik^2 over the entries of the current row so far.
  double Remaining() const { return remaining_; }

 private:
  double w_[kMaxDimension][kMaxDimension] = {};
  double remaining_ = 1.0;
};

template <int N>
void FillMatrix(const double* variance,
                const CorrelationFactor& w,
                Eigen::Matrix<double, N, N>* m) {
  for (int i = 0; i < N; ++i) {
    (*m)(i, i) = variance[i];
    for (int j = 0; j < i; ++j) {
      const double value = std::sqrt(variance[i]) * std::sqrt(variance[j]) * w.Correlation(i, j);
      (*m)(i, j) = value;
      (*m)(j, i) = value;
    }
  }
}

}  // namespace

double MaxEncodableVariance() {
  return std::exp2(kLogVarianceMin + (kLogVarianceMaxCode + 0.5) * kLogVarianceStep);
}

double VarianceFromCode(uint8_t code) {
  return std::exp2(kLogVarianceMin + code * kLogVarianceStep);
}

uint8_t VarianceCode(double variance) {
  if (!(variance > 0.0)) return 0;
  const double steps = (std::log2(variance) - kLogVarianceMin) / kLogVarianceStep;
  return static_cast<uint8_t>(std::clamp<long>(std::lround(steps), 0, kLogVarianceMaxCode));
}

template <int N>
void EncodeCovariance(const Eigen::Matrix<double, N, N>& m, uint8_t* codes) {
  static_assert(N >= 1 && N <= kMaxDimension);
  double sigma[N];
  for (int i = 0; i < N; ++i) {
    codes[i] = VarianceCode(m(i, i));
    sigma[i] = std::sqrt(std::max(m(i, i), 0.0));
  }
  CorrelationFactor w;
  int next = N;
  for (int i = 0; i < N; ++i) {
    w.BeginRow();
    for (int j = 0; j < i; ++j) {
      double rho = 0.0;
      if (sigma[i] > 0.0 && sigma[j] > 0.0) {
        rho = std::clamp(m(j, i) / sigma[i] / sigma[j], -1.0, 1.0);  // upper triangle
      }
      // The W_ij that makes the decoded rho_ij exact, given the quantized
      // W_jk and W_ik (k < j); as a partial correlation of row i.
      const double target = (rho - w.PartialDot(i, j)) / w.Diagonal(j);
      const double scale = std::sqrt(w.Remaining());
      const int code = CorrelationCode(scale > 0.0 ? target / scale : 0.0);
      codes[next++] = static_cast<uint8_t>(static_cast<int8_t>(code));
      w.Append(i, j, CorrelationFromCode(code));
    }
    w.CloseRow(i);
  }
}

template <int N>
bool DecodeCovariance(const uint8_t* codes, Eigen::Matrix<double, N, N>* m, int* bad_code) {
  static_assert(N >= 1 && N <= kMaxDimension);
  double variance[N];
  for (int i = 0; i < N; ++i) variance[i] = VarianceFromCode(codes[i]);
  CorrelationFactor w;
  int next = N;
  for (int i = 0; i < N; ++i) {
    w.BeginRow();
    for (int j = 0; j < i; ++j) {
      const int code = static_cast<int8_t>(codes[next]);
      if (code < -kCorrelationMaxCode) {
        *bad_code = next;
        return false;
      }
      ++next;
      w.Append(i, j, CorrelationFromCode(code));
    }
    w.CloseRow(i);
  }
  FillMatrix<N>(variance, w, m);
  return true;
}

template void EncodeCovariance<3>(const Eigen::Matrix<double, 3, 3>&, uint8_t*);
template void EncodeCovariance<6>(const Eigen::Matrix<double, 6, 6>&, uint8_t*);
template bool DecodeCovariance<3>(const uint8_t*, Eigen::Matrix<double, 3, 3>*, int*);
template bool DecodeCovariance<6>(const uint8_t*, Eigen::Matrix<double, 6, 6>*, int*);

}  // namespace swarmlio::net::internal
