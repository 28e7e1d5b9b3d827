#include "mapless/io/lazy_ffmpeg.h"

#include <string>

#include "mapless/io/lazy_libraries.h"

// The folder of the FFmpeg the build linked against (io/CMakeLists.txt); empty: by soname only.
#ifndef MAPLESS_FFMPEG_LIBDIR
#define MAPLESS_FFMPEG_LIBDIR ""
#endif

namespace mapless::io::lazy {
namespace {

// A library by its soname (lib<name>.so.<major version of the headers built against>).
struct Library {
  std::string soname;
  void* handle = nullptr;
  Library(const std::string& name, int major)
      : soname("lib" + name + ".so." + std::to_string(major)) {
    const std::string dir = MAPLESS_FFMPEG_LIBDIR;
    const std::string path = dir.empty() ? std::string() : dir + "/" + soname;
    handle = OpenLibrary(path.c_str(), soname.c_str(), "to read video files");
  }
};

#define MAPLESS_FFMPEG_SYMBOL(lib, name) \
  name = reinterpret_cast<decltype(name)>(Symbol(lib.handle, #name, lib.soname.c_str()))

struct Loaded : Ffmpeg {
  Loaded() {
    const Library avutil("avutil", LIBAVUTIL_VERSION_MAJOR);
    const Library avcodec("avcodec", LIBAVCODEC_VERSION_MAJOR);
    const Library avformat("avformat", LIBAVFORMAT_VERSION_MAJOR);
    const Library swscale("swscale", LIBSWSCALE_VERSION_MAJOR);
    MAPLESS_FFMPEG_SYMBOL(avutil, av_dict_free);
    MAPLESS_FFMPEG_SYMBOL(avutil, av_dict_set);
    MAPLESS_FFMPEG_SYMBOL(avutil, av_frame_alloc);
    MAPLESS_FFMPEG_SYMBOL(avutil, av_frame_free);
    MAPLESS_FFMPEG_SYMBOL(avutil, av_log_set_callback);
    MAPLESS_FFMPEG_SYMBOL(avutil, av_max_alloc);
    MAPLESS_FFMPEG_SYMBOL(avcodec, av_packet_alloc);
    MAPLESS_FFMPEG_SYMBOL(avcodec, av_packet_free);
    MAPLESS_FFMPEG_SYMBOL(avcodec, av_packet_unref);
    MAPLESS_FFMPEG_SYMBOL(avcodec, avcodec_alloc_context3);
    MAPLESS_FFMPEG_SYMBOL(avcodec, avcodec_free_context);
    MAPLESS_FFMPEG_SYMBOL(avcodec, avcodec_open2);
    MAPLESS_FFMPEG_SYMBOL(avcodec, avcodec_parameters_to_context);
    MAPLESS_FFMPEG_SYMBOL(avcodec, avcodec_receive_frame);
    MAPLESS_FFMPEG_SYMBOL(avcodec, avcodec_send_packet);
    MAPLESS_FFMPEG_SYMBOL(avformat, av_find_best_stream);
    MAPLESS_FFMPEG_SYMBOL(avformat, av_read_frame);
    MAPLESS_FFMPEG_SYMBOL(avformat, avformat_close_input);
    MAPLESS_FFMPEG_SYMBOL(avformat, avformat_find_stream_info);
    MAPLESS_FFMPEG_SYMBOL(avformat, avformat_open_input);
    MAPLESS_FFMPEG_SYMBOL(swscale, sws_freeContext);
    MAPLESS_FFMPEG_SYMBOL(swscale, sws_getCachedContext);
    MAPLESS_FFMPEG_SYMBOL(swscale, sws_scale);
  }
};

#undef MAPLESS_FFMPEG_SYMBOL

}  // namespace

const Ffmpeg& LoadFfmpeg() {
  static const Loaded ffmpeg;  // thread-safe; a failed load is tried again on the next call
  return ffmpeg;
}

}  // namespace mapless::io::lazy
