// The `mapless` command line. Subcommands live in cmd_*.cc; this file only dispatches and turns
// exceptions into one clear error line and an exit code (0 ok, 1 run failed, 2 bad input/usage).
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <string>

#include "builtin_middlewares.h"
#include "cli_common.h"
#include "fleet.h"
#include "interrupt.h"
#include "mapless/core/check.h"
#include "mapless/core/warning.h"
#include "mapless/run/report.h"
#include "mapless/run/text.h"

namespace {

// The error on one line, whatever it quotes: control characters (a newline in a file name) are
// written as escapes.
std::string OneLine(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (u < 0x20 || u == 0x7f) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "\\x%02x", u);
      out += hex;
    } else {
      out += c;
    }
  }
  return out;
}

// --help in 100 columns: CLI11 2.1 does not wrap, and descriptions ran to 393 characters.
class WrappingFormatter : public CLI::Formatter {
 public:
  std::string make_option(const CLI::Option* opt, bool is_positional) const override {
    return Wrap(make_option_name(opt, is_positional) + make_option_opts(opt),
                make_option_desc(opt));
  }
  std::string make_description(const CLI::App* app) const override {
    std::string out;
    for (const std::string& line :
         mapless::run::WrapWords(CLI::Formatter::make_description(app), 100))
      out += line + "\n";
    return out.substr(0, out.size() - 1);  // the text ended with a newline
  }
  std::string make_subcommand(const CLI::App* sub) const override {
    return Wrap(sub->get_display_name(), sub->get_description());
  }

 private:
  std::string Wrap(const std::string& left, const std::string& text) const {
    const std::size_t column = column_width_;
    std::string out = "  " + left;
    out += out.size() >= column ? "\n" + std::string(column, ' ')
                                : std::string(column - out.size(), ' ');
    const auto lines = mapless::run::WrapWords(text, 100 - column);
    for (std::size_t k = 0; k < lines.size(); ++k)
      out += (k > 0 ? "\n" + std::string(column, ' ') : "") + lines[k];
    return out + "\n";
  }
};

// `mapless --version`: the version and the robot links this build has.
std::string VersionText() {
  std::string links;
  for (const std::string& n : mapless::app::BuiltinMiddlewares().names())
    links += (links.empty() ? "" : ", ") + n;
  return std::string("mapless ") + MAPLESS_VERSION + "\nrobot links: " +
         (links.empty() ? "none (simulator, recordings, videos and cameras only; "
                          "scripts/setup.sh --ros, then build again, for ROS 1 and ROS 2)"
                        : links);
}

// An empty value is no value: `--live ""` ran without a live view, `eval lifelong --only ""` ran
// the whole suite, as if the option had not been given. No option of mapless takes "" to mean
// anything, so an empty argument is refused, naming the option before it (or its place).
void RefuseEmptyArguments(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const std::size_t eq = arg.find('=');
    if (arg.rfind("--", 0) == 0 && eq != std::string::npos && eq + 1 == arg.size())
      throw mapless::InputError(arg.substr(0, eq) + ": an empty value");
    if (!arg.empty()) continue;
    const std::string before = i > 1 ? argv[i - 1] : "";
    if (before.rfind("-", 0) == 0 && before.size() > 1)
      throw mapless::InputError(before + ": an empty value");
    throw mapless::InputError("argument " + std::to_string(i) + " is empty" +
                              (before.empty() ? "" : " (after '" + before + "')"));
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"mapless: appearance-based robot navigation from one uncalibrated camera, no map"};
  app.require_subcommand(1);
  app.formatter(std::make_shared<WrappingFormatter>());
  app.set_version_flag("--version", VersionText());
  // Logs go to stderr: stdout carries only results (JSON, tables, lists).
  spdlog::set_default_logger(spdlog::stderr_color_mt("mapless"));
  // On a terminal each log line first erases the line, where a progress line may stand.
  spdlog::set_pattern(::isatty(STDERR_FILENO) == 1 ? "\r\033[K%^[%l]%$ %v" : "%^[%l]%$ %v");
  cv::setNumThreads(1);
  // OpenCV's own log lines (video back ends probing a file) would break "one error line": every
  // failure reaches the user as mapless's own message instead.
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  mapless::app::InstallInterruptHandlers();
  mapless::run::SetInvocation(MAPLESS_VERSION, argc, argv);
  mapless::SetWarningSink([](const std::string& line) { spdlog::warn("{}", line); });
  mapless::app::AddDemoCommand(&app);
  mapless::app::AddSimCommands(&app);
  mapless::app::AddTeachRepeatCommands(&app);
  mapless::app::AddFollowCommand(&app);
  mapless::app::AddLeadCommand(&app);
  mapless::app::AddTeleopCommand(&app);
  mapless::app::AddFleetCommand(&app);
  mapless::app::AddShiftCommand(&app);
  mapless::app::AddFlowCommand(&app);
  mapless::app::AddGroundCommand(&app);
  mapless::app::AddNavigateCommand(&app);
  mapless::app::AddLocalizeCommand(&app);
  mapless::app::AddEvalCommand(&app);
  mapless::app::AddSoakCommand(&app);
  mapless::app::AddBenchCommand(&app);
  try {
    RefuseEmptyArguments(argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "mapless: error: " << OneLine(e.what()) << " (see --help)\n";
    return mapless::app::kExitBadInput;
  } catch (const mapless::app::Interrupted& e) {
    std::cerr << "mapless: " << e.what() << ": stopped cleanly, every finished file kept\n";
    return e.exit_code();
  } catch (const mapless::InputError& e) {
    std::cerr << "mapless: error: " << OneLine(e.what()) << "\n";
    return mapless::app::kExitBadInput;
  } catch (const mapless::app::RunFailed& e) {
    std::cerr << "mapless: " << OneLine(e.what()) << "\n";
    return mapless::app::kExitRunFailed;
  } catch (const std::filesystem::filesystem_error& e) {
    // A path of the user's that the library could not follow (a symlink loop, no permission):
    // the path and the reason, not the library's "filesystem error: status: ..." line. A disk
    // that is full or failing is the run's failure, not bad input.
    std::string paths = e.path1().string();
    if (!e.path2().empty()) paths += " -> " + e.path2().string();
    const int code = e.code().value();
    std::cerr << "mapless: error: " << OneLine(paths) << ": " << OneLine(e.code().message())
              << "\n";
    return code == ENOSPC || code == EIO || code == EDQUOT ? mapless::app::kExitRunFailed
                                                           : mapless::app::kExitBadInput;
  } catch (const cv::Exception& e) {
    // Inputs are checked before they reach OpenCV; one that still trips it is a mapless bug.
    std::cerr << "mapless: error: internal (OpenCV " << e.func << "): " << OneLine(e.err)
              << "; please report this with the command line\n";
    return mapless::app::kExitRunFailed;
  } catch (const std::exception& e) {
    std::cerr << "mapless: error: " << OneLine(e.what()) << "\n";
    return mapless::app::kExitRunFailed;
  }
  // The results go to standard output: when they could not all be written (`--json >` a full
  // disk, a closed pipe) the run has failed, whatever it computed.
  std::cout.flush();
  errno = 0;
  if (!std::cout.good() || std::fflush(stdout) != 0 || std::ferror(stdout)) {
    const int err = errno;
    std::cerr << "mapless: error: standard output: the results could not be written ("
              << (err != 0 ? std::strerror(err) : "write error") << ")\n";
    return mapless::app::kExitRunFailed;
  }
  return 0;
}
