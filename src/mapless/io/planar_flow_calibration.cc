#include "mapless/io/planar_flow_calibration.h"

#include <cmath>
#include <sstream>

#include "mapless/core/check.h"
#include "mapless/io/yaml_reader.h"

namespace mapless::io {
namespace {

// A ground homography of one frame period: finite, invertible, and moving the ground (the
// navigator divides by the mean flow of each). A zero matrix, or the identity, is no calibration;
// it was taken to the scene ("the dominant plane does not move like the ground").
void CheckModel(const cv::Mat& m, const char* field, int width, int height) {
  MAPLESS_CHECK(m.rows == 3 && m.cols == 3 && m.type() == CV_64F && cv::checkRange(m),
                "PlanarFlowCalibration." << field << ": expected a finite 3x3 matrix");
  const double scale = cv::norm(m);
  MAPLESS_CHECK(scale > 0.0 && std::abs(cv::determinant(m / scale)) > 1e-12,
                field << ": a singular homography (all zeros?) is not a motion of the ground");
  double moved = 0.0;
  int points = 0;
  for (int i = 0; i <= 4; ++i)
    for (int j = 0; j <= 4; ++j) {
      const double x = width * i / 4.0, y = height * j / 4.0;
      const double w = m.at<double>(2, 0) * x + m.at<double>(2, 1) * y + m.at<double>(2, 2);
      if (std::abs(w) < 1e-12) continue;
      const double u = (m.at<double>(0, 0) * x + m.at<double>(0, 1) * y + m.at<double>(0, 2)) / w;
      const double v = (m.at<double>(1, 0) * x + m.at<double>(1, 1) * y + m.at<double>(1, 2)) / w;
      moved += std::hypot(u - x, v - y);
      ++points;
    }
  MAPLESS_CHECK(points > 0 && moved / points > 1e-3,
                field << ": the homography moves no pixel (the identity?): the calibrated flow "
                         "is zero (did the robot move?)");
}

}  // namespace

void PlanarFlowCalibration::Validate() const {
  MAPLESS_CHECK(width > 0 && height > 0, "PlanarFlowCalibration: width and height must be > 0");
  MAPLESS_CHECK(period_s > 0.0, "PlanarFlowCalibration.period_s = " << period_s << "; must be > 0");
  MAPLESS_CHECK(speed_mps > 0.0,
                "PlanarFlowCalibration.speed_mps = " << speed_mps << "; must be > 0");
  MAPLESS_CHECK(omega_radps > 0.0,
                "PlanarFlowCalibration.omega_radps = " << omega_radps << "; must be > 0");
  MAPLESS_CHECK(width <= 16384 && height <= 16384,
                "PlanarFlowCalibration: width and height must be at most 16384");
  CheckModel(translational, "translational", width, height);
  CheckModel(rotational, "rotational", width, height);
}

std::string CalibrationToYaml(const PlanarFlowCalibration& c) {
  c.Validate();
  std::ostringstream out;
  out.precision(17);
  auto row = [&](const char* key, const cv::Mat& m) {
    out << key << ": [";
    for (int i = 0; i < 9; ++i) out << (i ? ", " : "") << m.at<double>(i / 3, i % 3);
    out << "]\n";
  };
  out << "# mapless planar-flow calibration (visual potential, Section 4.3): ground homographies\n"
      << "# of one frame period, row-major, driving straight ahead and turning counter-clockwise.\n"
      << "format: mapless-planar-flow-calibration\nversion: 1\n"
      << "width: " << c.width << "\nheight: " << c.height << "\nperiod_s: " << c.period_s
      << "\nspeed_mps: " << c.speed_mps << "\nomega_radps: " << c.omega_radps << "\n";
  row("translational", c.translational);
  row("rotational", c.rotational);
  return out.str();
}

static PlanarFlowCalibration CalibrationFromYamlUnchecked(const std::string& text,
                                                          const std::string& source) {
  const YamlMap y = YamlMap::LoadString(text, source);
  y.CheckKnownKeys({"format", "version", "width", "height", "period_s", "speed_mps", "omega_radps",
                    "translational", "rotational"});
  if (y.GetString("format") != "mapless-planar-flow-calibration")
    y.Fail("format", "expected 'mapless-planar-flow-calibration'");
  if (y.GetInt("version") != 1) y.Fail("version", "unsupported version (this build reads 1)");
  PlanarFlowCalibration c;
  c.width = y.GetInt("width");
  c.height = y.GetInt("height");
  c.period_s = y.GetDouble("period_s");
  c.speed_mps = y.GetDouble("speed_mps");
  c.omega_radps = y.GetDouble("omega_radps");
  auto model = [&](const char* key) {
    const std::vector<double> v = y.GetDoubles(key, 9);
    cv::Mat m(3, 3, CV_64F);
    for (int i = 0; i < 9; ++i) m.at<double>(i / 3, i % 3) = v[static_cast<std::size_t>(i)];
    return m;
  };
  c.translational = model("translational");
  c.rotational = model("rotational");
  try {
    c.Validate();
  } catch (const InputError& e) {
    throw InputError(source + ": " + e.what());
  }
  return c;
}

PlanarFlowCalibration CalibrationFromYaml(const std::string& text, const std::string& source) {
  return WithYamlErrors(source, [&] { return CalibrationFromYamlUnchecked(text, source); });
}

}  // namespace mapless::io
