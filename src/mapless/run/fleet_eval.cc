// `mapless eval fleet` (fleet_eval.h).
#include "mapless/run/fleet_eval.h"

#include <signal.h>
#include <stdlib.h>

#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <thread>

#include "mapless/core/check.h"
#include "mapless/fleet/curve.h"
#include "mapless/io/atomic_file.h"
#include "mapless/run/processes.h"
#include "mapless/run/text.h"

namespace mapless::run {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

void Say(const FleetEvalOptions& a, const std::string& line) {
  if (a.say) a.say("eval fleet: " + line);
}

}  // namespace

namespace {

// The processes of an evaluation and their links.
struct Fleet {
  std::string work;  // the work directory: routes, logs, keys, summaries
  std::string scenario;
  Child leader{{}, ""};
  std::vector<Child> followers;
  std::unique_ptr<Relay> relay;  // the last follower's link, when it is to be cut
  int relay_port = 0;
};

struct Faults {
  bool follower_killed = false;
  int leader_restarts = 0;
  int follower_restarts = 0;
};

// The work directory, the ports, the keys and each process's command line (none started yet).
Fleet Prepare(const FleetEvalOptions& a) {
  if (a.method != "funnel" && a.method != "eigenspace")
    throw InputError("--method " + a.method + ": must be funnel or eigenspace");
  const std::string scenario = !a.scenario.empty()    ? a.scenario
                               : a.method == "funnel" ? "table1_almost_straight"
                                                      : "office_aliasing";
  Fleet f;
  f.scenario = scenario;
  std::string& work = f.work;
  work = a.keep;
  if (work.empty()) {
    char tmpl[] = "/tmp/mapless-fleet-XXXXXX";
    MAPLESS_CHECK(::mkdtemp(tmpl) != nullptr, "eval fleet: cannot make a temporary directory");
    work = tmpl;
  } else {
    MAPLESS_CHECK(!fs::exists(work) || fs::is_empty(work), "--keep " << work << ": not empty");
    fs::create_directories(work);
  }
  const int port = FreePort();
  const std::string endpoint = "tcp://127.0.0.1:" + std::to_string(port);
  std::vector<std::string> curve_leader, curve_follower;
  if (a.curve) {
    fleet::GenerateCurveKey(work + "/leader.key");
    fleet::GenerateCurveKey(work + "/follower.key");
    curve_leader = {"--curve-key", work + "/leader.key", "--curve-allow",
                    work + "/follower.key.pub"};
    curve_follower = {"--curve-key", work + "/follower.key", "--curve-leader",
                      work + "/leader.key.pub"};
  }
  const std::string rate = std::to_string(a.rate);
  std::vector<std::string> lead_args = {"mapless",
                                        "lead",
                                        "--source",
                                        "sim:" + scenario,
                                        "--route",
                                        work + "/leader",
                                        "--bind",
                                        endpoint,
                                        "--method",
                                        a.method,
                                        "--real-time-factor",
                                        rate};
  lead_args.insert(lead_args.end(), curve_leader.begin(), curve_leader.end());
  f.leader = Child(lead_args, work + "/leader.log", a.program);
  if (a.link_down_at_s > 0.0) {
    f.relay_port = FreePort();
    f.relay = std::make_unique<Relay>(f.relay_port, port);
  }
  for (int i = 1; i <= a.followers; ++i) {
    const std::string name = "follower" + std::to_string(i);
    const bool relayed = f.relay && i == a.followers;
    std::vector<std::string> args = {
        "mapless",
        "follow",
        "--connect",
        relayed ? "tcp://127.0.0.1:" + std::to_string(f.relay_port) : endpoint,
        "--source",
        "sim:" + scenario,
        "--route",
        work + "/" + name,
        "--real-time-factor",
        rate,
        "--summary",
        work + "/" + name + ".json",
        "--seed",
        std::to_string(a.seed + static_cast<std::uint64_t>(i))};
    args.insert(args.end(), curve_follower.begin(), curve_follower.end());
    f.followers.emplace_back(args, work + "/" + name + ".log", a.program);
  }
  return f;
}

// Starts the processes, makes the faults asked for at their times, and ends every process once
// the followers are done (or at the time limit, or when `each_tick` throws).
Faults Supervise(Fleet& f, const FleetEvalOptions& a, Clock::time_point t0) {
  f.leader.Start();
  Faults faults;
  bool started = false, leader_killed = false, link_cut = false, link_restored = false;
  // Generous: the route at the given rate, twice, plus the start delay and the faults.
  const double limit_s = 900.0;
  try {
    while (true) {
      if (a.each_tick) a.each_tick();
      const double t = SecondsSince(t0);
      if (!started && t >= a.start_after_s) {
        for (Child& c : f.followers) c.Start();
        started = true;
      }
      if (a.kill_leader_at_s > 0.0 && !leader_killed && t >= a.kill_leader_at_s) {
        f.leader.Signal(SIGKILL);
        f.leader.Wait(5.0);
        f.leader.Start();
        leader_killed = true;
        ++faults.leader_restarts;
        Say(a, Format("killed the leader at %.1f s and started it again", t));
      }
      if (a.kill_follower_at_s > 0.0 && started && !faults.follower_killed &&
          t >= a.kill_follower_at_s) {
        f.followers[0].Signal(SIGKILL);
        f.followers[0].Wait(5.0);
        f.followers[0].Start();
        faults.follower_killed = true;
        ++faults.follower_restarts;
        Say(a, Format("killed follower 1 at %.1f s and started it again", t));
      }
      if (f.relay && !link_cut && t >= a.link_down_at_s) {
        f.relay->Down();
        link_cut = true;
        Say(a, Format("follower %d's link down at %.1f s", a.followers, t));
      }
      if (f.relay && link_cut && !link_restored && t >= a.link_down_at_s + a.link_down_for_s) {
        f.relay->Up();
        link_restored = true;
        Say(a, Format("follower %d's link up again at %.1f s", a.followers, t));
      }
      bool all_done = started;
      for (Child& c : f.followers) all_done = c.Poll() && all_done;
      if (all_done && (!f.relay || link_restored || a.link_down_at_s > t)) break;
      if (t > limit_s) {
        Say(a, Format("time limit of %.0f s", limit_s));
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  } catch (...) {
    for (Child& c : f.followers) c.Signal(SIGINT);
    f.leader.Signal(SIGINT);
    for (Child& c : f.followers) c.Wait(5.0);
    f.leader.Wait(5.0);
    throw;
  }
  for (Child& c : f.followers) {
    c.Signal(SIGINT);
    c.Wait(10.0);
  }
  f.leader.Signal(SIGINT);
  f.leader.Wait(10.0);
  f.relay.reset();

  return faults;
}

// Each follower's summary, and whether its copy is the leader's route byte for byte.
FleetEvalOutput Collect(const Fleet& f, const Faults& faults, const FleetEvalOptions& a,
                        double wall_s) {
  const auto leader_files = DirectoryFiles(f.work + "/leader");
  nlohmann::json j;
  j["suite"] = "fleet";
  j["method"] = a.method;
  j["scenario"] = f.scenario;
  j["followers"] = a.followers;
  j["rate"] = a.rate;
  j["leader_restarts"] = faults.leader_restarts;
  j["follower_restarts"] = faults.follower_restarts;
  j["link_down_s"] = f.relay_port ? a.link_down_for_s : 0.0;
  j["curve"] = a.curve;
  j["wall_s"] = wall_s;
  std::string table;
  Appendf(&table, "%-10s %-9s %8s %8s %8s %8s %5s %5s %8s %9s %9s\n", "follower", "completed",
          "lateral", "final", "received", "applied", "gaps", "dups", "copy", "lat med", "lat p99");
  bool ok = true;
  for (int i = 1; i <= a.followers; ++i) {
    const std::string name = "follower" + std::to_string(i);
    nlohmann::json s;
    try {
      s = nlohmann::json::parse(io::ReadFile(f.work + "/" + name + ".json", 1 << 20));
    } catch (const std::exception&) {
      s["completed"] = false;
      s["reason"] = "no summary (see " + f.work + "/" + name + ".log)";
    }
    const auto copy_files = DirectoryFiles(f.work + "/" + name);
    const bool identical = !leader_files.empty() && copy_files == leader_files;
    // Gaps: records of the leader's route missing from the copy (every file of the leader's route
    // that the copy lacks or holds different bytes of); duplicates: records applied twice would
    // have been refused by the copy, so they are counted from the copy's refusals.
    int gaps = 0;
    for (const auto& [path, bytes] : leader_files) {
      const auto it = copy_files.find(path);
      gaps += it == copy_files.end() || it->second != bytes;
    }
    s["copy_identical"] = identical;
    s["gaps"] = gaps;
    s["duplicates_applied"] = s.value("rejected", 0);
    s["follower"] = i;
    s["restarted"] = faults.follower_killed && i == 1;
    s["link_cut"] = f.relay_port && i == a.followers;
    const bool good =
        s.value("completed", false) && identical && gaps == 0 && s.value("rejected", 0) == 0;
    ok = ok && good;
    Appendf(&table, "%-10s %-9s %7.3fm %7.3fm %8d %8d %5d %5d %8s %7.2fms %7.2fms\n", name.c_str(),
            s.value("completed", false) ? "yes" : "NO", s.value("lateral_rms_m", -1.0),
            s.value("final_error_m", -1.0), s.value("records_received", 0),
            s.value("records_applied", 0), gaps, s.value("rejected", 0),
            identical ? "same" : "DIFFERS", s.value("latency_median_ms", -1.0),
            s.value("latency_p99_ms", -1.0));
    j["results"].push_back(s);
  }
  j["ok"] = ok;
  if (a.keep.empty()) fs::remove_all(f.work);
  return {j, table, ok};
}

}  // namespace

FleetEvalOutput RunFleetEval(const FleetEvalOptions& a) {
  Fleet fleet = Prepare(a);
  const auto t0 = Clock::now();
  const Faults faults = Supervise(fleet, a, t0);
  return Collect(fleet, faults, a, SecondsSince(t0));
}

}  // namespace mapless::run
