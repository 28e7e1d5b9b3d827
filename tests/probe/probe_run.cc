// probe_run: runs one command for the bad-input probe (probe.sh) and reports how it ended.
//
//   probe_run TIMEOUT_S OUT_FILE ERR_FILE -- COMMAND [ARGS...]
//
// Runs COMMAND in its own process group with standard input from /dev/null and its output in the
// two files; kills the group after TIMEOUT_S seconds. Prints one line
//   exit=N peak_rss_kb=K wall_ms=W timed_out=0|1
// (N is 128 + the signal for a process ended by a signal). The peak resident memory comes from
// wait4(2), so it is the command's own, measured by the kernel. Exits 0 when it could run COMMAND.
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <thread>

int main(int argc, char** argv) {
  if (argc < 6 || std::strcmp(argv[4], "--") != 0) {
    std::fprintf(stderr, "usage: probe_run TIMEOUT_S OUT_FILE ERR_FILE -- COMMAND [ARGS...]\n");
    return 2;
  }
  const double timeout_s = std::atof(argv[1]);
  const auto start = std::chrono::steady_clock::now();
  const pid_t pid = fork();
  if (pid < 0) {
    std::perror("probe_run: fork");
    return 2;
  }
  if (pid == 0) {
    setpgid(0, 0);
    const int in = open("/dev/null", O_RDONLY);
    const int out = open(argv[2], O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = open(argv[3], O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0) _exit(127);
    dup2(in, 0);
    dup2(out, 1);
    dup2(err, 2);
    execvp(argv[5], argv + 5);
    _exit(127);
  }
  setpgid(pid, pid);
  int status = 0;
  rusage usage{};
  bool timed_out = false;
  while (true) {
    const pid_t done = wait4(pid, &status, WNOHANG, &usage);
    if (done == pid) break;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!timed_out && elapsed > timeout_s) {
      timed_out = true;
      kill(-pid, SIGKILL);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  kill(-pid, SIGKILL);  // anything the command left behind in its group
  const long wall_ms = static_cast<long>(
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::printf("exit=%d peak_rss_kb=%ld wall_ms=%ld timed_out=%d\n", code, usage.ru_maxrss, wall_ms,
              timed_out ? 1 : 0);
  return 0;
}
