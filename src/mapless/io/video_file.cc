#include "mapless/io/video_file.h"

#include <sys/stat.h>

#include <cstdarg>
#include <cstdint>
#include <mutex>

#include "mapless/core/check.h"
#include "mapless/io/image_file.h"
#include "mapless/io/lazy_ffmpeg.h"
#include "mapless/io/limits.h"

namespace mapless::io {
namespace {

const lazy::Ffmpeg& Ff() { return lazy::LoadFfmpeg(); }

// FFmpeg prints its own messages ("moov atom not found") to stderr; a file that cannot be read is
// reported as one InputError instead, so they are dropped.
extern "C" void QuietFfmpegLog(void*, int, const char*, va_list) {}

// The largest single allocation FFmpeg may make: a 40-megapixel frame in 4 bytes a pixel is 160 MB.
// (A malformed file made a demuxer ask for 1.9 GB; found by the video_file fuzzer.)
constexpr std::size_t kMaxFfmpegAllocation = std::size_t{256} << 20;

void ConfigureFfmpeg() {
  static std::once_flag once;
  std::call_once(once, [] {
    Ff().av_log_set_callback(QuietFfmpegLog);
    Ff().av_max_alloc(kMaxFfmpegAllocation);
  });
}

// The containers and codecs of cameras, phones, dashcams and robot recordings; FFmpeg's other
// demuxers and decoders (hundreds, some printing to stderr on their own) are not offered a file.
constexpr const char* kContainers = "avi,mov,matroska,mpegts,mpeg,flv,ogg,asf,mjpeg,h264,hevc,m4v";
constexpr const char* kCodecs =
    "h264,hevc,mpeg4,mjpeg,vp8,vp9,av1,libdav1d,libaom-av1,mpeg1video,mpeg2video,rawvideo,theora,"
    "msmpeg4v2,msmpeg4v3,wmv1,wmv2,wmv3,vc1,h263,flv,png,ffv1";

struct FormatCloser {
  void operator()(AVFormatContext* f) const { Ff().avformat_close_input(&f); }
};
struct DecoderFreer {
  void operator()(AVCodecContext* c) const { Ff().avcodec_free_context(&c); }
};
struct PacketFreer {
  void operator()(AVPacket* p) const { Ff().av_packet_free(&p); }
};
struct FrameFreer {
  void operator()(AVFrame* f) const { Ff().av_frame_free(&f); }
};
struct ScalerFreer {
  void operator()(SwsContext* s) const { Ff().sws_freeContext(s); }
};

// Decoding a hostile file must end: packets read per decoded frame are bounded.
constexpr int kMaxPacketsPerFrame = 10'000;

class FfmpegVideo : public FrameSource {
 public:
  explicit FfmpegVideo(const std::string& path) : path_(path) {
    ConfigureFfmpeg();
    // FFmpeg would wait for a writer on a FIFO and read /dev/zero for ever.
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
      Fail(": not a regular file (a video file must be one; cameras are camera:N or /dev/videoN)");
    }
    AVDictionary* options = nullptr;
    Ff().av_dict_set(&options, "format_whitelist", kContainers, 0);
    Ff().av_dict_set(&options, "codec_whitelist", kCodecs, 0);
    AVFormatContext* format = nullptr;  // freed by avformat_open_input when it fails
    const int opened = Ff().avformat_open_input(&format, path.c_str(), nullptr, &options);
    Ff().av_dict_free(&options);
    if (opened < 0) {
      Fail(
          ": cannot open video (missing file, or not a video in a container mapless reads: "
          "AVI, MP4/MOV, MKV/WebM, MPEG-TS/PS, FLV, Ogg, ASF, raw MJPEG/H.264/H.265)");
    }
    format_.reset(format);
    if (Ff().avformat_find_stream_info(format_.get(), nullptr) < 0) {
      Fail(": cannot read the video's streams");
    }
    const AVCodec* codec = nullptr;
    stream_ = Ff().av_find_best_stream(format_.get(), AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
    if (stream_ < 0 || codec == nullptr) Fail(": no video stream that FFmpeg can decode");
    const AVStream* stream = format_->streams[stream_];
    CheckFrameSize(stream->codecpar->width, stream->codecpar->height, path_);
    decoder_.reset(Ff().avcodec_alloc_context3(codec));
    if (!decoder_ || Ff().avcodec_parameters_to_context(decoder_.get(), stream->codecpar) < 0) {
      Fail(": cannot set up the video decoder");
    }
    decoder_->thread_count = 1;  // deterministic, and mapless runs one thread per method
    AVDictionary* codec_options = nullptr;
    Ff().av_dict_set(&codec_options, "codec_whitelist", kCodecs, 0);
    const int decoder_open = Ff().avcodec_open2(decoder_.get(), codec, &codec_options);
    Ff().av_dict_free(&codec_options);
    if (decoder_open < 0) {
      Fail(": cannot decode its video codec '" + std::string(codec->name) + "' (mapless reads " +
           kCodecs + ")");
    }
    const AVRational rate =
        stream->avg_frame_rate.num > 0 ? stream->avg_frame_rate : stream->r_frame_rate;
    const double fps = rate.den > 0 ? av_q2d(rate) : 0.0;
    fps_ = fps > 0.0 && fps < 1000.0 ? fps : 30.0;
    packet_.reset(Ff().av_packet_alloc());
    frame_.reset(Ff().av_frame_alloc());
    if (!packet_ || !frame_) Fail(": out of memory");
  }

  bool Next(Frame* out) override {
    if (!Decode()) return false;
    const std::string name = path_ + " frame " + std::to_string(index_);
    CheckFrameSize(frame_->width, frame_->height, name);
    const cv::Size size(frame_->width, frame_->height);
    if (!size_.empty() && size != size_) {
      throw InputError(name + ": image is " + std::to_string(size.width) + "x" +
                       std::to_string(size.height) + " but the first frame is " +
                       std::to_string(size_.width) + "x" + std::to_string(size_.height));
    }
    size_ = size;
    // Converted at the decoded frame's own size, into a buffer of that size.
    scaler_.reset(Ff().sws_getCachedContext(scaler_.release(), frame_->width, frame_->height,
                                            static_cast<AVPixelFormat>(frame_->format),
                                            frame_->width, frame_->height, AV_PIX_FMT_GRAY8,
                                            SWS_BILINEAR, nullptr, nullptr, nullptr));
    if (!scaler_) throw InputError(name + ": a pixel format mapless cannot convert");
    cv::Mat grey(frame_->height, frame_->width, CV_8UC1);
    std::uint8_t* planes[4] = {grey.data, nullptr, nullptr, nullptr};
    const int strides[4] = {static_cast<int>(grey.step), 0, 0, 0};
    if (Ff().sws_scale(scaler_.get(), frame_->data, frame_->linesize, 0, frame_->height, planes,
                       strides) != frame_->height) {
      throw InputError(name + ": the frame does not convert to grey");
    }
    out->image = grey;
    out->t_ns = FromSeconds(static_cast<double>(index_) / fps_);
    out->name = std::to_string(index_);
    ++index_;
    return true;
  }

  std::string Describe() const override { return path_; }

 private:
  [[noreturn]] void Fail(const std::string& why) const { throw InputError(path_ + why); }

  // The next decoded frame into frame_; false at the end of the stream. A frame that does not
  // decode is skipped, as players do; a file that yields nothing decodable ends.
  bool Decode() {
    for (int packets = 0; packets < kMaxPacketsPerFrame; ++packets) {
      const int received = Ff().avcodec_receive_frame(decoder_.get(), frame_.get());
      if (received == 0) return true;
      if (received == AVERROR_EOF) return false;
      if (received != AVERROR(EAGAIN)) {
        if (++bad_frames_ > kMaxPacketsPerFrame) return false;
        continue;
      }
      if (flushing_) return false;
      const int read = Ff().av_read_frame(format_.get(), packet_.get());
      if (read < 0) {
        flushing_ = true;
        Ff().avcodec_send_packet(decoder_.get(), nullptr);  // drain the decoder
        continue;
      }
      if (packet_->stream_index == stream_) Ff().avcodec_send_packet(decoder_.get(), packet_.get());
      Ff().av_packet_unref(packet_.get());
    }
    throw InputError(path_ + ": no frame decodes from " + std::to_string(kMaxPacketsPerFrame) +
                     " packets");
  }

  std::string path_;
  std::unique_ptr<AVFormatContext, FormatCloser> format_;
  std::unique_ptr<AVCodecContext, DecoderFreer> decoder_;
  std::unique_ptr<AVPacket, PacketFreer> packet_;
  std::unique_ptr<AVFrame, FrameFreer> frame_;
  std::unique_ptr<SwsContext, ScalerFreer> scaler_;
  int stream_ = -1;
  double fps_ = 30.0;
  long index_ = 0;
  int bad_frames_ = 0;
  bool flushing_ = false;
  cv::Size size_;
};

}  // namespace

std::unique_ptr<FrameSource> OpenVideoFile(const std::string& path) {
  return std::make_unique<FfmpegVideo>(path);
}

}  // namespace mapless::io
