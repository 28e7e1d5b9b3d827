// The FFmpeg functions io/video_file.cc calls, loaded on the first video file (io/lazy_libraries.h
// says why). Each is the library's own function, called through a pointer of its declared type.
#pragma once

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include <libavutil/log.h>
#include <libavutil/mem.h>
#include <libswscale/swscale.h>
}

namespace mapless::io::lazy {

struct Ffmpeg {
  // libavutil
  decltype(&::av_dict_free) av_dict_free = nullptr;
  decltype(&::av_dict_set) av_dict_set = nullptr;
  decltype(&::av_frame_alloc) av_frame_alloc = nullptr;
  decltype(&::av_frame_free) av_frame_free = nullptr;
  decltype(&::av_log_set_callback) av_log_set_callback = nullptr;
  decltype(&::av_max_alloc) av_max_alloc = nullptr;
  // libavcodec
  decltype(&::av_packet_alloc) av_packet_alloc = nullptr;
  decltype(&::av_packet_free) av_packet_free = nullptr;
  decltype(&::av_packet_unref) av_packet_unref = nullptr;
  decltype(&::avcodec_alloc_context3) avcodec_alloc_context3 = nullptr;
  decltype(&::avcodec_free_context) avcodec_free_context = nullptr;
  decltype(&::avcodec_open2) avcodec_open2 = nullptr;
  decltype(&::avcodec_parameters_to_context) avcodec_parameters_to_context = nullptr;
  decltype(&::avcodec_receive_frame) avcodec_receive_frame = nullptr;
  decltype(&::avcodec_send_packet) avcodec_send_packet = nullptr;
  // libavformat
  decltype(&::av_find_best_stream) av_find_best_stream = nullptr;
  decltype(&::av_read_frame) av_read_frame = nullptr;
  decltype(&::avformat_close_input) avformat_close_input = nullptr;
  decltype(&::avformat_find_stream_info) avformat_find_stream_info = nullptr;
  decltype(&::avformat_open_input) avformat_open_input = nullptr;
  // libswscale
  decltype(&::sws_freeContext) sws_freeContext = nullptr;
  decltype(&::sws_getCachedContext) sws_getCachedContext = nullptr;
  decltype(&::sws_scale) sws_scale = nullptr;
};

// The functions, loaded on the first call (thread-safe); throws std::runtime_error naming a
// library that does not load or a function it lacks.
const Ffmpeg& LoadFfmpeg();

}  // namespace mapless::io::lazy
