#include "swarmlio/eval/trajectory_io.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <system_error>
#include <vector>

namespace swarmlio::eval {

namespace {

constexpr size_t kTumValues = 8;
constexpr size_t kKittiValues = 12;
// EuRoC: #timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w, q_RS_x, q_RS_y,
// q_RS_z, then columns we ignore (velocity, biases in the ground truth).
constexpr size_t kEurocValues = 8;
constexpr double kNsPerS = 1e9;
// A quaternion this close to zero has no defined rotation.
constexpr double kMinQuaternionNorm = 1e-9;

std::string Where(const std::string& path, int line_number) {
  return path + ":" + std::to_string(line_number) + ": ";
}

/// Splits on spaces and tabs. Returns false if the line is a comment or empty.
bool Tokenize(std::string line, std::vector<std::string>* tokens) {
  tokens->clear();
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const size_t first = line.find_first_not_of(" \t");
  if (first == std::string::npos || line[first] == '#') return false;
  size_t pos = first;
  while (pos < line.size()) {
    const size_t end = line.find_first_of(" \t", pos);
    tokens->push_back(line.substr(pos, end == std::string::npos ? std::string::npos : end - pos));
    if (end == std::string::npos) break;
    pos = line.find_first_not_of(" \t", end);
    if (pos == std::string::npos) break;
  }
  return true;
}

/// Splits a CSV line on ',' and trims spaces and tabs around each value.
/// Returns false if the line is empty or starts with '#' (evo's rule).
bool TokenizeCsv(std::string line, std::vector<std::string>* tokens) {
  tokens->clear();
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t") == std::string::npos) {
    return false;
  }
  size_t pos = 0;
  while (true) {
    const size_t end = line.find(',', pos);
    std::string value = line.substr(pos, end == std::string::npos ? std::string::npos : end - pos);
    const size_t first = value.find_first_not_of(" \t");
    const size_t last = value.find_last_not_of(" \t");
    tokens->push_back(first == std::string::npos ? "" : value.substr(first, last - first + 1));
    if (end == std::string::npos) break;
    pos = end + 1;
  }
  return true;
}

/// Parses exactly `count` finite numbers (locale independent, correctly
/// rounded like strtod, so the doubles equal numpy's).
Status ParseNumbers(const std::vector<std::string>& tokens, size_t count, double* values) {
  if (tokens.size() != count) {
    return Status::InvalidArgument("expected " + std::to_string(count) + " values, got " +
                                   std::to_string(tokens.size()));
  }
  for (size_t k = 0; k < count; ++k) {
    const std::string& token = tokens[k];
    const char* begin = token.data();
    const char* end = token.data() + token.size();
    if (begin != end && *begin == '+') ++begin;
    const std::from_chars_result parsed = std::from_chars(begin, end, values[k]);
    if (parsed.ec != std::errc() || parsed.ptr != end) {
      return Status::InvalidArgument("value " + std::to_string(k + 1) + " '" + token +
                                     "' is not a number");
    }
    if (!std::isfinite(values[k])) {
      return Status::InvalidArgument("value " + std::to_string(k + 1) + " '" + token +
                                     "' is not finite");
    }
  }
  return Status::Ok();
}

Status OpenForReading(const std::string& path, std::ifstream* file) {
  file->open(path);
  if (!file->is_open()) return Status::NotFound(path + ": cannot open trajectory file");
  return Status::Ok();
}

Status FinishReading(const std::string& path, const std::ifstream& file, const Trajectory& out) {
  if (file.bad()) return Status::IoError(path + ": read error");
  if (out.empty()) return Status::InvalidArgument(path + ": no poses in file");
  return Status::Ok();
}

// Reads a pose file line by line: comments and blank lines are skipped and
// counted, every other line must hold exactly N finite numbers, which go to
// `on_line(line_number, tokens, values, &trajectory, &stats)`.
template <size_t N, class OnLine>
Status ReadPoseLines(const std::string& path, Trajectory* trajectory, TrajectoryReadStats* stats,
                     OnLine&& on_line) {
  std::ifstream file;
  SWARMLIO_RETURN_IF_ERROR(OpenForReading(path, &file));
  Trajectory out;
  TrajectoryReadStats counts;
  std::string line;
  std::vector<std::string> tokens;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    if (!Tokenize(line, &tokens)) {
      ++counts.skipped_lines;
      continue;
    }
    std::array<double, N> v{};
    const Status parsed = ParseNumbers(tokens, N, v.data());
    if (!parsed.ok()) {
      const std::string hint = line.find(',') != std::string::npos
                                   ? " (comma-separated: EuRoC ground truth is read with the "
                                     "euroc format)"
                                   : "";
      return Status::InvalidArgument(Where(path, line_number) + parsed.message() + hint);
    }
    SWARMLIO_RETURN_IF_ERROR(on_line(line_number, tokens, v, &out, &counts));
  }
  SWARMLIO_RETURN_IF_ERROR(FinishReading(path, file, out));
  counts.pose_lines = static_cast<int>(out.size());
  *trajectory = std::move(out);
  if (stats != nullptr) *stats = counts;
  return Status::Ok();
}

// Appends one stamped pose of a TUM or EuRoC file: the stamp must increase
// (equal only with allow_duplicate_stamps), the quaternion must not be zero
// and is normalised.
Status AppendStampedPose(const std::string& path,
                         int line_number,
                         const std::string& stamp_text,
                         double stamp_s,
                         const Eigen::Vector3d& position,
                         Eigen::Quaterniond q_G_b,
                         const TrajectoryReadOptions& options,
                         int* previous_line,
                         Trajectory* out,
                         TrajectoryReadStats* counts) {
  if (out->has_stamps()) {
    const double previous_s = out->stamps_s.back();
    const bool equal = stamp_s == previous_s;
    if (stamp_s < previous_s || (equal && !options.allow_duplicate_stamps)) {
      return Status::InvalidArgument(
          Where(path, line_number) + "stamp " + stamp_text + " does not increase (line " +
          std::to_string(*previous_line) + ")" +
          (equal ? "; equal stamps are accepted with allow_duplicate_stamps" : ""));
    }
    if (equal) ++counts->duplicate_stamps;
  }
  if (q_G_b.norm() < kMinQuaternionNorm) {
    return Status::InvalidArgument(Where(path, line_number) + "zero quaternion");
  }
  q_G_b.normalize();
  Eigen::Isometry3d T_G_b = Eigen::Isometry3d::Identity();
  T_G_b.linear() = q_G_b.toRotationMatrix();
  T_G_b.translation() = position;
  out->stamps_s.push_back(stamp_s);
  out->T_G_b.push_back(T_G_b);
  *previous_line = line_number;
  return Status::Ok();
}

Status OpenForWriting(const std::string& path, std::FILE** file) {
  *file = std::fopen(path.c_str(), "w");
  if (*file == nullptr) return Status::IoError(path + ": cannot open for writing");
  return Status::Ok();
}

Status CloseWritten(const std::string& path, std::FILE* file, bool write_ok) {
  const bool close_ok = std::fclose(file) == 0;
  if (!write_ok || !close_ok) return Status::IoError(path + ": write failed");
  return Status::Ok();
}

}  // namespace

bool TrajectoryFormatFromString(const std::string& text, TrajectoryFormat* format) {
  if (text == "tum") {
    *format = TrajectoryFormat::kTum;
  } else if (text == "kitti") {
    *format = TrajectoryFormat::kKitti;
  } else if (text == "euroc") {
    *format = TrajectoryFormat::kEuroc;
  } else {
    return false;
  }
  return true;
}

Status ReadTumTrajectory(const std::string& path,
                         const TrajectoryReadOptions& options,
                         Trajectory* trajectory,
                         TrajectoryReadStats* stats) {
  int previous_line = 0;
  return ReadPoseLines<kTumValues>(
      path, trajectory, stats,
      [&](int line_number, const std::vector<std::string>& tokens,
          const std::array<double, kTumValues>& v, Trajectory* out, TrajectoryReadStats* counts) {
        // File order is x y z w; Eigen's constructor takes w x y z.
        return AppendStampedPose(
            path, line_number, tokens[0], v[0], Eigen::Vector3d(v[1], v[2], v[3]),
            Eigen::Quaterniond(v[7], v[4], v[5], v[6]), options, &previous_line, out, counts);
      });
}

Status ReadEurocTrajectory(const std::string& path,
                           const TrajectoryReadOptions& options,
                           Trajectory* trajectory,
                           TrajectoryReadStats* stats) {
  std::ifstream file;
  SWARMLIO_RETURN_IF_ERROR(OpenForReading(path, &file));
  Trajectory out;
  TrajectoryReadStats counts;
  std::string line;
  std::vector<std::string> tokens;
  int line_number = 0;
  int previous_line = 0;
  while (std::getline(file, line)) {
    ++line_number;
    if (!TokenizeCsv(line, &tokens)) {
      ++counts.skipped_lines;
      continue;
    }
    if (tokens.size() < kEurocValues) {
      return Status::InvalidArgument(
          Where(path, line_number) + "expected at least " + std::to_string(kEurocValues) +
          " comma-separated values (timestamp [ns], p_RS_R_x y z [m], q_RS_w x y z), got " +
          std::to_string(tokens.size()));
    }
    tokens.resize(kEurocValues);  // further columns are ignored
    std::array<double, kEurocValues> v{};
    const Status parsed = ParseNumbers(tokens, kEurocValues, v.data());
    if (!parsed.ok()) return Status::InvalidArgument(Where(path, line_number) + parsed.message());
    // evo: float64(stamp in ns) / 1e9, quaternion w x y z.
    SWARMLIO_RETURN_IF_ERROR(AppendStampedPose(
        path, line_number, tokens[0], v[0] / kNsPerS, Eigen::Vector3d(v[1], v[2], v[3]),
        Eigen::Quaterniond(v[4], v[5], v[6], v[7]), options, &previous_line, &out, &counts));
  }
  SWARMLIO_RETURN_IF_ERROR(FinishReading(path, file, out));
  counts.pose_lines = static_cast<int>(out.size());
  *trajectory = std::move(out);
  if (stats != nullptr) *stats = counts;
  return Status::Ok();
}

Status ReadKittiTrajectory(const std::string& path,
                           Trajectory* trajectory,
                           TrajectoryReadStats* stats) {
  return ReadPoseLines<kKittiValues>(
      path, trajectory, stats,
      [&](int line_number, const std::vector<std::string>&,
          const std::array<double, kKittiValues>& v, Trajectory* out, TrajectoryReadStats*) {
        Eigen::Isometry3d T_G_b = Eigen::Isometry3d::Identity();
        for (int r = 0; r < 3; ++r) {
          for (int c = 0; c < 4; ++c) T_G_b.matrix()(r, c) = v[static_cast<size_t>(4 * r + c)];
        }
        const Eigen::Matrix3d R = T_G_b.linear();
        const double orthonormality_error =
            (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
        if (orthonormality_error > kMaxOrthonormalityError || R.determinant() <= 0.0) {
          return Status::InvalidArgument(Where(path, line_number) +
                                         "the 3 x 3 block is not a rotation (|R^T R - I| = " +
                                         std::to_string(orthonormality_error) + ")");
        }
        out->T_G_b.push_back(T_G_b);
        return Status::Ok();
      });
}

Status ReadTrajectory(const std::string& path,
                      TrajectoryFormat format,
                      const TrajectoryReadOptions& options,
                      Trajectory* trajectory,
                      TrajectoryReadStats* stats) {
  switch (format) {
    case TrajectoryFormat::kTum:
      return ReadTumTrajectory(path, options, trajectory, stats);
    case TrajectoryFormat::kKitti:
      return ReadKittiTrajectory(path, trajectory, stats);
    case TrajectoryFormat::kEuroc:
      return ReadEurocTrajectory(path, options, trajectory, stats);
  }
  return Status::InvalidArgument("unknown trajectory format");
}

Status WriteTumTrajectory(const std::string& path, const Trajectory& trajectory) {
  SWARMLIO_RETURN_IF_ERROR(ValidateTrajectory(trajectory, path));
  if (!trajectory.has_stamps()) {
    return Status::InvalidArgument(path + ": a TUM file needs stamps; the trajectory has none");
  }
  std::FILE* file = nullptr;
  SWARMLIO_RETURN_IF_ERROR(OpenForWriting(path, &file));
  bool ok = std::fprintf(file, "# timestamp tx ty tz qx qy qz qw\n") > 0;
  for (size_t i = 0; ok && i < trajectory.size(); ++i) {
    const Eigen::Isometry3d& T = trajectory.T_G_b[i];
    const Eigen::Quaterniond q_G_b(Eigen::Matrix3d(T.linear()));
    const Eigen::Vector3d& p = T.translation();
    ok = std::fprintf(file, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                      trajectory.stamps_s[i], p.x(), p.y(), p.z(), q_G_b.x(), q_G_b.y(), q_G_b.z(),
                      q_G_b.w()) > 0;
  }
  return CloseWritten(path, file, ok);
}

Status WriteKittiTrajectory(const std::string& path, const Trajectory& trajectory) {
  SWARMLIO_RETURN_IF_ERROR(ValidateTrajectory(trajectory, path));
  std::FILE* file = nullptr;
  SWARMLIO_RETURN_IF_ERROR(OpenForWriting(path, &file));
  bool ok = true;
  for (size_t i = 0; ok && i < trajectory.size(); ++i) {
    const Eigen::Matrix4d& M = trajectory.T_G_b[i].matrix();
    for (int r = 0; ok && r < 3; ++r) {
      for (int c = 0; ok && c < 4; ++c) {
        ok = std::fprintf(file, (r == 2 && c == 3) ? "%.17g\n" : "%.17g ", M(r, c)) > 0;
      }
    }
  }
  return CloseWritten(path, file, ok);
}

}  // namespace swarmlio::eval
