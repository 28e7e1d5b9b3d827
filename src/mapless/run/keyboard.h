// The keyboard of the terminal mapless runs in, for `mapless teleop`: standard input switched to
// raw mode (each key as it is typed, no echo; Ctrl-C and Ctrl-D arrive as keys) and read without
// waiting. The terminal's mode is restored when the Keyboard ends. When standard input is not a
// terminal (a pipe, a file) its bytes are read as they come, and its end is the end of the keys.
#pragma once

#include <termios.h>

#include "mapless/robot/teleop.h"

namespace mapless::run {

class Keyboard {
 public:
  explicit Keyboard(int fd = 0);
  ~Keyboard();
  Keyboard(const Keyboard&) = delete;
  Keyboard& operator=(const Keyboard&) = delete;

  // The bytes typed since the last call (never waits); closed once the input ended or the
  // terminal went away.
  robot::KeyInput Read();
  bool is_terminal() const { return terminal_; }

 private:
  int fd_;
  bool terminal_ = false;
  bool closed_ = false;
  termios saved_{};
};

}  // namespace mapless::run
