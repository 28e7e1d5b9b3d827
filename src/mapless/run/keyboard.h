// The keyboard of the terminal mapless runs in, for `mapless teleop`: standard input switched to
// raw mode (each key as it is typed, no echo; Ctrl-C and Ctrl-D arrive as keys) and read without
// waiting. The terminal's mode is restored when the Keyboard ends. When standard input is not a
// terminal (a pipe, a file) its bytes are read as they come, and its end is the end of the keys.
//
// A thread of its own reads the input as it comes, so that what ends teleop is heard at once,
// frames or not: Ctrl-C, Ctrl-D, the end of the input or a terminal that went away call `on_end`
// (teleop: mapless::RequestInterrupt, which every wait of a robot link checks within
// milliseconds). Before the first camera frame no method step reads the keys; they used to wait
// for the camera's give-up, or for ever with it disabled.
#pragma once

#include <termios.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "mapless/robot/teleop.h"

namespace mapless::run {

class Keyboard {
 public:
  explicit Keyboard(int fd = 0, std::function<void()> on_end = {});
  ~Keyboard();  // stops the reader, then restores the terminal
  Keyboard(const Keyboard&) = delete;
  Keyboard& operator=(const Keyboard&) = delete;

  // The bytes typed since the last call (never waits); closed once the input ended or the
  // terminal went away.
  robot::KeyInput Read();
  bool is_terminal() const { return terminal_; }
  // Ctrl-C or Ctrl-D was typed, or the input ended.
  bool ended() const { return ended_.load(); }

 private:
  void ReadLoop();

  int fd_;
  bool terminal_ = false;
  termios saved_{};
  std::function<void()> on_end_;
  std::mutex mu_;
  std::string bytes_;    // typed, not yet Read() (at most 64 KB: more is dropped)
  bool closed_ = false;  //
  std::atomic<bool> ended_{false};
  std::atomic<bool> stop_{false};
  std::thread reader_;
};

}  // namespace mapless::run
