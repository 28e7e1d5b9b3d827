#include "cli_common.h"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <vector>

#include "mapless/core/check.h"
#include "mapless/io/atomic_file.h"
#include "mapless/io/image_file.h"
#include "mapless/io/limits.h"

namespace mapless::app {

std::vector<double> ParseNumbers(const std::string& text, const std::string& option, int n,
                                 const std::string& form) {
  const std::string error =
      option + " '" + text + "': expected " + form + " (" + std::to_string(n) + " numbers)";
  std::vector<double> v;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      std::size_t used = 0;
      v.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(v.back())) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError(error);
    }
  }
  if (static_cast<int>(v.size()) != n) throw InputError(error);
  return v;
}

void SwitchingArgs::ApplyTo(navigation::RepeatOptions* options) const {
  if (end != "scale" && end != "switching")
    throw InputError("--end '" + end + "': expected scale or switching");
  options->switching = navigation::ParseSwitching(switching);
  options->end_by_local_scale = end == "scale";
  options->redetect_every_frames = redetect_every;
  options->recovery_keyframes = recover_keyframes;
  options->carry_on.max_distance_m = carry_on_m;
}

void AddSwitchingOptions(CLI::App* cmd, SwitchingArgs* a) {
  cmd->add_option("--switching", a->switching,
                  "stdratio (Kassir et al.), mse (Chen & Birchfield) or scale (local scale of "
                  "nearby features, not in the papers)")
      ->capture_default_str();
  cmd->add_option("--end", a->end,
                  "How the last keyframe is passed: scale (local scale of nearby features, robust "
                  "to a lateral offset) or switching (like every other keyframe)")
      ->capture_default_str();
  cmd->add_option("--redetect-every", a->redetect_every,
                  "Detect and match afresh every N frames, KLT tracking in between (0: only when "
                  "features run short, as in Algorithm 1)")
      ->capture_default_str()
      ->check(CLI::Range(0, 1000));
  cmd->add_option("--recover-keyframes", a->recover_keyframes,
                  "Keyframe recovery: after 2 s waiting for an unmatched keyframe, also try up to "
                  "N following keyframes (0: off, as in the paper; "
                  "docs/teach_and_repeat.md#keyframe-recovery)")
      ->capture_default_str()
      ->check(CLI::Range(0, 20));
  cmd->add_option("--carry-on-m", a->carry_on_m,
                  "When no keyframe matches and recovery finds none: drive the taught path by "
                  "odometry for at most this many metres, matching the following keyframes "
                  "(needs a route taught with odometry; 0: off; docs/teach_and_repeat.md, "
                  "Carrying on)")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
}

Pose2 ParsePoseDeg(const std::string& text, const std::string& option) {
  const std::vector<double> v = ParseNumbers(text, option, 3, "X,Y,THETA_DEG");
  // A heading of 1e300 degrees is no heading (it rendered): ten turns either way at most, the
  // limit of a taught rotation.
  if (!(std::abs(v[2]) <= 3600.0))
    throw InputError(option + " " + text + ": THETA_DEG " + text.substr(text.rfind(',') + 1) +
                     " is beyond ten turns (-3600 to 3600 degrees)");
  return Pose2{v[0], v[1], WrapAngle(DegToRad(v[2]))};
}

JsonLines::JsonLines(const std::string& path, bool in_place) {
  if (path.empty() || path == "-") return;
  file_ = std::make_unique<io::JournalFile>(
      path, in_place ? io::JournalFile::Mode::kInPlace : io::JournalFile::Mode::kReplaceAtClose);
}

CLI::Validator SeedCheck() {
  return CLI::Validator(
      [](const std::string& text) -> std::string {
        const bool digits = !text.empty() && text.size() <= 20 &&
                            text.find_first_not_of("0123456789") == std::string::npos;
        if (!digits || (text.size() == 20 && text > "18446744073709551615")) {
          return "'" + text + "' is not a seed (a whole number from 0 to 2^64 - 1)";
        }
        return "";
      },
      "", "Seed");
}

CLI::Validator FiniteIn(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](const std::string& text) -> std::string {
        double v = 0.0;
        std::size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          return "'" + text + "' is not a number";
        }
        if (used != text.size() || !std::isfinite(v) || v < lo || v > hi) {
          std::ostringstream out;
          out << "'" << text << "' is not a number in [" << lo << ", " << hi << "]";
          return out.str();
        }
        return "";
      },
      "", "FiniteIn");
}

CLI::Validator ZeroOrIn(double lo, double hi) {
  const CLI::Validator in = FiniteIn(lo, hi);
  return CLI::Validator(
      [in, lo, hi](std::string& text) -> std::string {
        if (FiniteIn(0.0, 0.0)(text).empty()) return "";
        if (in(text).empty()) return "";
        std::ostringstream out;
        out << "'" << text << "' is neither 0 nor a number in [" << lo << ", " << hi << "]";
        return out.str();
      },
      "", "ZeroOrIn");
}

void RefuseOutputOverInputs(const std::string& output, const std::string& option,
                            const std::vector<std::string>& inputs) {
  namespace fs = std::filesystem;
  if (output.empty() || output == "-") return;
  std::error_code ec;
  const fs::path out = fs::weakly_canonical(fs::absolute(output, ec), ec);
  for (const std::string& input : inputs) {
    if (input.empty()) continue;
    std::error_code e2;
    const fs::path in = fs::weakly_canonical(fs::absolute(input, e2), e2);
    if (e2) continue;
    const bool same = out == in || (fs::exists(out, e2) && fs::equivalent(out, in, e2));
    // Inside an input directory (a route, an image folder)?
    const auto within = [](const fs::path& a, const fs::path& dir) {
      const auto rel = a.lexically_relative(dir);
      return !rel.empty() && *rel.begin() != "..";
    };
    // The output inside an input directory, or an input inside the output directory.
    const bool inside = (fs::is_directory(in, e2) && within(out, in)) ||
                        (fs::is_directory(out, e2) && within(in, out));
    if (same || inside) {
      throw InputError(option + " " + output + ": would overwrite the input " + input +
                       "; write the output elsewhere");
    }
  }
}

void JsonLines::Write(const nlohmann::json& j) {
  if (file_) {
    file_->Append(j.dump());
    return;
  }
  std::cout << j.dump() << "\n";
  std::cout.flush();
}

sim::DriveOptions LoadDriveOptions(const std::string& config_path) {
  if (config_path.empty()) return sim::DriveOptions{};
  return sim::ParseDriveOptions(io::ReadFile(config_path, io::kMaxYamlFileBytes), config_path);
}

cv::Mat ReadImageOrThrow(const std::string& path, int flags) {
  return io::ReadImage(path, flags, io::kMinImageSide);
}

}  // namespace mapless::app
