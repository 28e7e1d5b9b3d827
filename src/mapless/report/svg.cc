#include "mapless/report/svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <tuple>

namespace mapless::report {
namespace {

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f", v);
  return buf;
}

// A tick label: as few digits as the tick step needs.
std::string TickLabel(double v, double step) {
  char buf[32];
  const int digits = step >= 1.0 ? 0 : std::min(4, static_cast<int>(std::ceil(-std::log10(step))));
  std::snprintf(buf, sizeof(buf), "%.*f", digits, std::abs(v) < 1e-12 ? 0.0 : v);
  return buf;
}

// A "nice" tick step (1, 2 or 5 times a power of ten) for about `n` ticks over `span`.
double NiceStep(double span, int n) {
  if (!(span > 0.0)) return 1.0;
  const double raw = span / n;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (raw <= m * p) return m * p;
  return 10.0 * p;
}

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool empty() const { return !(lo <= hi); }
  void Pad() {
    if (empty()) lo = 0.0, hi = 1.0;
    if (hi - lo < 1e-9) lo -= 0.5, hi += 0.5;
  }
};

std::string Text(double x, double y, const std::string& s, const char* anchor = "start",
                 int size = 11, const char* extra = "") {
  return "<text x=\"" + Num(x) + "\" y=\"" + Num(y) + "\" font-size=\"" + std::to_string(size) +
         "\" text-anchor=\"" + anchor + "\" fill=\"#333\"" + extra + ">" + Escape(s) + "</text>\n";
}

}  // namespace

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string LinePlotSvg(const PlotSpec& spec) {
  const double w = spec.width_px, h = spec.height_px;
  const double left = 58, right = 12, top = spec.title.empty() ? 12 : 26, bottom = 50;
  Range xr, yr;
  for (const Series& s : spec.series) {
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      xr.Add(s.x[i]);
      yr.Add(s.y[i]);
    }
  }
  const bool no_data = xr.empty();
  xr.Pad();
  yr.Pad();
  const double y_step = NiceStep(yr.hi - yr.lo, 4);
  yr.lo = std::floor(yr.lo / y_step) * y_step;
  yr.hi = std::ceil(yr.hi / y_step) * y_step;
  const double x_step = NiceStep(xr.hi - xr.lo, 6);
  const double pw = w - left - right, ph = h - top - bottom;
  const auto X = [&](double x) { return left + (x - xr.lo) / (xr.hi - xr.lo) * pw; };
  const auto Y = [&](double y) { return top + (yr.hi - y) / (yr.hi - yr.lo) * ph; };
  // The legend in rows as wide as the plot (ten runs' labels do not fit one); each row after the
  // first makes the picture 16 px taller.
  std::vector<double> legend_rows;
  double legend_x = 0.0, legend_row = 0.0;
  for (const Series& s : spec.series) {
    if (s.label.empty()) continue;
    const double width = 34 + 6.0 * static_cast<double>(s.label.size());
    if (legend_x > 0.0 && legend_x + width > pw) legend_row += 1.0, legend_x = 0.0;
    legend_rows.push_back(legend_row);
    legend_x += width;
  }
  const double total_h = h + 16.0 * legend_row;
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << total_h
    << "\" viewBox=\"0 0 " << w << ' ' << total_h
    << "\" font-family=\"sans-serif\" role=\"img\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"#fff\"/>\n";
  if (!spec.title.empty()) o << Text(left, 16, spec.title, "start", 13, " font-weight=\"bold\"");
  for (double y = yr.lo; y <= yr.hi + 1e-9 * y_step; y += y_step) {
    o << "<line x1=\"" << Num(left) << "\" x2=\"" << Num(left + pw) << "\" y1=\"" << Num(Y(y))
      << "\" y2=\"" << Num(Y(y)) << "\" stroke=\"#e4e4e4\"/>\n";
    o << Text(left - 5, Y(y) + 4, TickLabel(y, y_step), "end", 10);
  }
  for (double x = std::ceil(xr.lo / x_step) * x_step; x <= xr.hi + 1e-9 * x_step; x += x_step) {
    o << "<line x1=\"" << Num(X(x)) << "\" x2=\"" << Num(X(x)) << "\" y1=\"" << Num(top)
      << "\" y2=\"" << Num(top + ph) << "\" stroke=\"#f0f0f0\"/>\n";
    o << Text(X(x), top + ph + 14, TickLabel(x, x_step), "middle", 10);
  }
  o << "<rect x=\"" << Num(left) << "\" y=\"" << Num(top) << "\" width=\"" << Num(pw)
    << "\" height=\"" << Num(ph) << "\" fill=\"none\" stroke=\"#888\"/>\n";
  o << Text(left + pw / 2, top + ph + 30, spec.x_label, "middle");
  o << "<text transform=\"translate(13," << Num(top + ph / 2)
    << ") rotate(-90)\" font-size=\"11\" text-anchor=\"middle\" fill=\"#333\">"
    << Escape(spec.y_label) << "</text>\n";
  if (no_data) o << Text(left + pw / 2, top + ph / 2, "no data", "middle", 12);
  for (const Series& s : spec.series) {
    if (s.points) {
      for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
        if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
        o << "<circle cx=\"" << Num(X(s.x[i])) << "\" cy=\"" << Num(Y(s.y[i]))
          << "\" r=\"1.6\" fill=\"" << Escape(s.color) << "\"/>\n";
      }
      continue;
    }
    std::string d;
    bool pen_down = false;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) {
        pen_down = false;
        continue;
      }
      d += (pen_down ? "L" : "M") + Num(X(s.x[i])) + "," + Num(Y(s.y[i]));
      pen_down = true;
    }
    if (d.empty()) continue;
    o << "<path d=\"" << d << "\" fill=\"none\" stroke=\"" << Escape(s.color)
      << "\" stroke-width=\"1.6\"" << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
  }
  double lx = left;
  std::size_t entry = 0;
  for (const Series& s : spec.series) {
    if (s.label.empty()) continue;
    if (entry > 0 && legend_rows[entry] != legend_rows[entry - 1]) lx = left;
    const double ly = h - 8 + 16.0 * legend_rows[entry++];
    o << "<line x1=\"" << Num(lx) << "\" x2=\"" << Num(lx + 18) << "\" y1=\"" << Num(ly - 4)
      << "\" y2=\"" << Num(ly - 4) << "\" stroke=\"" << Escape(s.color) << "\" stroke-width=\"3\""
      << (s.dashed ? " stroke-dasharray=\"5,3\"" : "") << "/>\n";
    o << Text(lx + 22, ly, s.label, "start", 10);
    lx += 34 + 6.0 * static_cast<double>(s.label.size());
  }
  o << "</svg>\n";
  return o.str();
}

namespace {

struct LegendEntry {
  std::string text;
  std::string color;
  std::string kind;  // "path", "wall", "box", "cylinder", "poster", "star"
};

double LegendWidth(const LegendEntry& e) { return 36.0 + 6.2 * static_cast<double>(e.text.size()); }

// The row of each entry when rows are at most `width` wide.
std::vector<double> LegendRows(const std::vector<LegendEntry>& legend, double width) {
  std::vector<double> rows;
  double x = 0.0;
  double row = 0.0;
  for (const LegendEntry& e : legend) {
    if (x > 0.0 && x + LegendWidth(e) > width) row += 1.0, x = 0.0;
    rows.push_back(row);
    x += LegendWidth(e);
  }
  return rows;
}

std::string LegendMark(const LegendEntry& e, double x, double y) {
  std::ostringstream o;
  const std::string c = Escape(e.color);
  if (e.kind == "box") {
    o << "<rect x=\"" << Num(x + 4) << "\" y=\"" << Num(y - 6)
      << "\" width=\"12\" height=\"12\" fill=\"" << c << "\" stroke=\"#5a5a5a\"/>";
  } else if (e.kind == "cylinder") {
    o << "<circle cx=\"" << Num(x + 10) << "\" cy=\"" << Num(y) << "\" r=\"6\" fill=\"" << c
      << "\" stroke=\"#5a5a5a\"/>";
  } else if (e.kind == "star") {
    o << "<text x=\"" << Num(x + 10) << "\" y=\"" << Num(y + 6)
      << "\" font-size=\"16\" text-anchor=\"middle\" fill=\"" << c << "\">&#9733;</text>";
  } else {
    o << "<line x1=\"" << Num(x) << "\" x2=\"" << Num(x + 20) << "\" y1=\"" << Num(y) << "\" y2=\""
      << Num(y) << "\" stroke=\"" << c << "\" stroke-width=\"3\"/>";
  }
  return o.str();
}

// The kinds of object the world has, each with its legend text and colour, in a fixed order.
std::vector<std::tuple<std::string, std::string, std::string>> ObjectKinds(
    const sim::World& world) {
  bool wall = false, box = false, cylinder = false, poster = false;
  for (const sim::WorldObject& obj : world.objects) {
    wall |= obj.kind == sim::ObjectKind::kWall;
    box |= obj.kind == sim::ObjectKind::kBox;
    cylinder |= obj.kind == sim::ObjectKind::kCylinder;
    poster |= obj.kind == sim::ObjectKind::kPoster;
  }
  std::vector<std::tuple<std::string, std::string, std::string>> kinds;
  if (wall) kinds.emplace_back("wall", "wall", "#3c3c3c");
  if (box) kinds.emplace_back("box", "box", "#d2beaa");
  if (cylinder) kinds.emplace_back("cylinder", "cylinder", "#aac8b4");
  if (poster) kinds.emplace_back("poster", "poster on a wall", "#c850c8");
  return kinds;
}

// The legend's entries in their rows below the map, and the 1 m scale bar.
std::string LegendSvg(const std::vector<LegendEntry>& legend, const std::vector<double>& rows,
                      double map_h, double w, double ppm) {
  std::ostringstream o;
  double lx = 8;
  for (std::size_t k = 0; k < legend.size(); ++k) {
    if (k > 0 && rows[k] != rows[k - 1]) lx = 8;
    const double ly = map_h + 18.0 + 18.0 * static_cast<double>(rows[k]);
    o << "<g class=\"legend-entry\" data-kind=\"" << legend[k].kind << "\">"
      << LegendMark(legend[k], lx, ly - 4) << Text(lx + 24, ly, legend[k].text, "start", 11)
      << "</g>\n";
    lx += LegendWidth(legend[k]);
  }
  o << "<line x1=\"" << Num(w - 12 - ppm) << "\" x2=\"" << Num(w - 12) << "\" y1=\""
    << Num(map_h + 14) << "\" y2=\"" << Num(map_h + 14)
    << "\" stroke=\"#000\" stroke-width=\"3\"/>\n";
  o << Text(w - 12 - ppm, map_h + 9, "1 m", "start", 10);
  return o.str();
}

}  // namespace

std::string TopDownSvg(const sim::World& world, const std::vector<PathSpec>& paths,
                       const std::vector<Eigen::Vector2d>& markers, int max_side_px) {
  Eigen::Vector4d b = sim::FootprintBounds(world);
  const auto grow = [&](double x, double y) {
    b[0] = std::min(b[0], x), b[1] = std::min(b[1], y);
    b[2] = std::max(b[2], x), b[3] = std::max(b[3], y);
  };
  for (const PathSpec& p : paths)
    for (const Pose2& q : p.poses) grow(q.x_m, q.y_m);
  for (const auto& m : markers) grow(m.x(), m.y());
  if (!(b[0] <= b[2] && b[1] <= b[3])) b = Eigen::Vector4d(-1, -1, 1, 1);
  const double margin = 0.8;
  b += Eigen::Vector4d(-margin, -margin, margin, margin);
  const double span = std::max(b[2] - b[0], b[3] - b[1]);
  const double ppm = std::min(60.0, max_side_px / span);
  const double w = std::max(320.0, std::ceil((b[2] - b[0]) * ppm));
  const double map_h = std::max(120.0, std::ceil((b[3] - b[1]) * ppm));
  // The legend below the map, in rows as wide as the map: one entry per labelled path, then what
  // the marks are.
  std::vector<LegendEntry> legend;
  for (const PathSpec& p : paths)
    if (!p.label.empty()) legend.push_back({p.label, p.color, "path"});
  for (const auto& [kind, text, colour] : ObjectKinds(world))
    legend.push_back({text, colour, kind});
  if (!markers.empty()) legend.push_back({"destination", "#008c00", "star"});
  const std::vector<double> rows = LegendRows(legend, w - 70.0);
  const double h = map_h + 22.0 + 18.0 * static_cast<double>(rows.empty() ? 1 : rows.back() + 1);
  const auto X = [&](double x) { return Num((x - b[0]) * ppm); };
  const auto Y = [&](double y) { return Num((b[3] - y) * ppm); };
  std::ostringstream o;
  o << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << w << "\" height=\"" << h
    << "\" viewBox=\"0 0 " << w << ' ' << h << "\" font-family=\"sans-serif\" role=\"img\">\n";
  o << "<rect width=\"100%\" height=\"100%\" fill=\"#fafafa\"/>\n";
  double grid = 1.0;
  while (span / grid > 60.0) grid *= 10.0;
  // Coordinates (metres, the world frame) every `label_step` grid lines along the bottom and left.
  const double label_step = NiceStep(span, 6) < grid ? grid : NiceStep(span, 6);
  const auto labelled = [&](double v) {
    return std::abs(std::remainder(v, label_step)) < 1e-6 * label_step;
  };
  for (double x = std::ceil(b[0] / grid) * grid; x <= b[2]; x += grid) {
    o << "<line x1=\"" << X(x) << "\" x2=\"" << X(x) << "\" y1=\"0\" y2=\"" << Num(map_h)
      << "\" stroke=\"#e8e8e8\"/>\n";
    if (labelled(x)) o << Text(std::stod(X(x)), map_h - 3, TickLabel(x, grid), "middle", 9);
  }
  for (double y = std::ceil(b[1] / grid) * grid; y <= b[3]; y += grid) {
    o << "<line x1=\"0\" x2=\"" << Num(w) << "\" y1=\"" << Y(y) << "\" y2=\"" << Y(y)
      << "\" stroke=\"#e8e8e8\"/>\n";
    if (labelled(y)) o << Text(3, std::stod(Y(y)) - 2, TickLabel(y, grid), "start", 9);
  }
  o << Text(w - 4, map_h - 3, "x (m)", "end", 9) << Text(3, 10, "y (m)", "start", 9);
  for (const sim::WorldObject& obj : world.objects) {
    switch (obj.kind) {
      case sim::ObjectKind::kWall:
        o << "<line x1=\"" << X(obj.a.x()) << "\" y1=\"" << Y(obj.a.y()) << "\" x2=\""
          << X(obj.b.x()) << "\" y2=\"" << Y(obj.b.y())
          << "\" stroke=\"#3c3c3c\" stroke-width=\"3\"/>\n";
        break;
      case sim::ObjectKind::kBox: {
        const double c = std::cos(obj.yaw_rad), s = std::sin(obj.yaw_rad);
        o << "<polygon points=\"";
        for (const auto& [u, v] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
          const double lx = 0.5 * u * obj.size_m.x(), ly = 0.5 * v * obj.size_m.y();
          o << X(obj.center.x() + c * lx - s * ly) << ',' << Y(obj.center.y() + s * lx + c * ly)
            << ' ';
        }
        o << "\" fill=\"#d2beaa\" stroke=\"#5a5a5a\"/>\n";
        break;
      }
      case sim::ObjectKind::kCylinder:
        o << "<circle cx=\"" << X(obj.center.x()) << "\" cy=\"" << Y(obj.center.y()) << "\" r=\""
          << Num(std::max(2.0, obj.radius_m * ppm)) << "\" fill=\"#aac8b4\" stroke=\"#5a5a5a\"/>\n";
        break;
      case sim::ObjectKind::kPoster: {
        const double c = std::cos(obj.yaw_rad + kPi / 2), s = std::sin(obj.yaw_rad + kPi / 2);
        const double hw = 0.5 * obj.size_m.x();
        o << "<line x1=\"" << X(obj.center.x() - c * hw) << "\" y1=\"" << Y(obj.center.y() - s * hw)
          << "\" x2=\"" << X(obj.center.x() + c * hw) << "\" y2=\"" << Y(obj.center.y() + s * hw)
          << "\" stroke=\"#c850c8\" stroke-width=\"2\"/>\n";
        break;
      }
    }
  }
  for (const auto& m : markers) {
    o << "<text x=\"" << X(m.x()) << "\" y=\"" << Num((b[3] - m.y()) * ppm + 6)
      << "\" font-size=\"18\" text-anchor=\"middle\" fill=\"#008c00\">&#9733;</text>\n";
  }
  // The first path (the reference) is drawn first and wide, and the driven paths on top of it: a
  // path that follows the reference closely stays visible, with the reference on both sides.
  for (auto it = paths.begin(); it != paths.end(); ++it) {
    if (it->poses.empty()) continue;
    const bool reference = it == paths.begin() && paths.size() > 1;
    o << "<polyline fill=\"none\" stroke=\"" << Escape(it->color) << "\" stroke-width=\""
      << Num(reference ? std::max(6.0, 3.0 * it->width_px) : it->width_px) << "\""
      << " stroke-linejoin=\"round\" points=\"";
    for (const Pose2& p : it->poses) o << X(p.x_m) << ',' << Y(p.y_m) << ' ';
    o << "\"/>\n";
    const Pose2& s = it->poses.front();
    const Pose2& e = it->poses.back();
    o << "<circle cx=\"" << X(s.x_m) << "\" cy=\"" << Y(s.y_m)
      << "\" r=\"4\" fill=\"none\" stroke=\"" << Escape(it->color) << "\" stroke-width=\"2\"/>\n";
    o << "<line x1=\"" << X(e.x_m) << "\" y1=\"" << Y(e.y_m) << "\" x2=\""
      << X(e.x_m + 0.35 * std::cos(e.theta_rad)) << "\" y2=\""
      << Y(e.y_m + 0.35 * std::sin(e.theta_rad)) << "\" stroke=\"" << Escape(it->color)
      << "\" stroke-width=\"3\"/>\n";
  }
  o << LegendSvg(legend, rows, map_h, w, ppm);
  o << "</svg>\n";
  return o.str();
}

}  // namespace mapless::report
