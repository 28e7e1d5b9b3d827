#include "mapless/io/lazy_libraries.h"

#include <dlfcn.h>

#include <stdexcept>

// The libraries the build linked against (io/CMakeLists.txt); empty: by soname only.
#ifndef MAPLESS_OPENCV_IMGCODECS_PATH
#define MAPLESS_OPENCV_IMGCODECS_PATH ""
#endif
#ifndef MAPLESS_OPENCV_VIDEOIO_PATH
#define MAPLESS_OPENCV_VIDEOIO_PATH ""
#endif
#ifndef MAPLESS_OPENCV_IMGCODECS_SONAME
#define MAPLESS_OPENCV_IMGCODECS_SONAME "libopencv_imgcodecs.so"
#endif
#ifndef MAPLESS_OPENCV_VIDEOIO_SONAME
#define MAPLESS_OPENCV_VIDEOIO_SONAME "libopencv_videoio.so"
#endif

namespace mapless::io::lazy {

void* OpenLibrary(const char* path, const char* soname, const char* needed_for) {
  void* library = path[0] != '\0' ? ::dlopen(path, RTLD_NOW | RTLD_LOCAL) : nullptr;
  if (library == nullptr) library = ::dlopen(soname, RTLD_NOW | RTLD_LOCAL);
  if (library == nullptr) {
    const char* why = ::dlerror();
    throw std::runtime_error(std::string("cannot load ") + soname + " (needed " + needed_for +
                             "): " + (why != nullptr ? why : "unknown error"));
  }
  return library;
}

void* Symbol(void* library, const char* symbol, const char* soname) {
  void* address = ::dlsym(library, symbol);
  if (address == nullptr) {
    throw std::runtime_error(std::string(soname) + " has no function " + symbol +
                             " (an OpenCV or FFmpeg other than the one mapless was built with?)");
  }
  return address;
}

namespace {

// The functions by their mangled names (Itanium C++ ABI, OpenCV 4's std::string signatures); a
// member function is a function of the object's address and its arguments.
struct ImgCodecs {
  using Decode = cv::Mat (*)(const cv::_InputArray&, int);
  using Encode = bool (*)(const std::string&, const cv::_InputArray&, std::vector<uchar>&,
                          const std::vector<int>&);
  Decode decode = nullptr;
  Encode encode = nullptr;

  ImgCodecs() {
    const char* soname = MAPLESS_OPENCV_IMGCODECS_SONAME;
    void* lib = OpenLibrary(MAPLESS_OPENCV_IMGCODECS_PATH, soname, "to read and write images");
    decode = reinterpret_cast<Decode>(Symbol(lib, "_ZN2cv8imdecodeERKNS_11_InputArrayEi", soname));
    encode = reinterpret_cast<Encode>(
        Symbol(lib,
               "_ZN2cv8imencodeERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEERKNS_11_"
               "InputArrayERSt6vectorIhSaIhEERKSB_IiSaIiEE",
               soname));
  }
};

const ImgCodecs& Codecs() {
  static const ImgCodecs codecs;  // thread-safe; a failed load is tried again on the next call
  return codecs;
}

struct VideoIo {
  using Construct = void (*)(cv::VideoCapture*);
  using OpenDevice = bool (*)(cv::VideoCapture*, int, int);
  using OpenName = bool (*)(cv::VideoCapture*, const std::string&, int);
  using IsOpened = bool (*)(const cv::VideoCapture*);
  using Read = bool (*)(cv::VideoCapture*, const cv::_OutputArray&);
  using Get = double (*)(const cv::VideoCapture*, int);
  Construct construct = nullptr;
  Construct destroy = nullptr;
  OpenDevice open_device = nullptr;
  OpenName open_name = nullptr;
  IsOpened is_opened = nullptr;
  Read read = nullptr;
  Get get = nullptr;

  VideoIo() {
    const char* soname = MAPLESS_OPENCV_VIDEOIO_SONAME;
    void* lib = OpenLibrary(MAPLESS_OPENCV_VIDEOIO_PATH, soname, "to open a camera");
    const auto symbol = [&](const char* name) { return Symbol(lib, name, soname); };
    construct = reinterpret_cast<Construct>(symbol("_ZN2cv12VideoCaptureC1Ev"));
    destroy = reinterpret_cast<Construct>(symbol("_ZN2cv12VideoCaptureD1Ev"));
    open_device = reinterpret_cast<OpenDevice>(symbol("_ZN2cv12VideoCapture4openEii"));
    open_name = reinterpret_cast<OpenName>(symbol(
        "_ZN2cv12VideoCapture4openERKNSt7__cxx1112basic_stringIcSt11char_traitsIcESaIcEEEi"));
    is_opened = reinterpret_cast<IsOpened>(symbol("_ZNK2cv12VideoCapture8isOpenedEv"));
    read = reinterpret_cast<Read>(symbol("_ZN2cv12VideoCapture4readERKNS_12_OutputArrayE"));
    get = reinterpret_cast<Get>(symbol("_ZNK2cv12VideoCapture3getEi"));
  }
};

const VideoIo& Video() {
  static const VideoIo video;
  return video;
}

}  // namespace

cv::Mat ImDecode(const cv::Mat& bytes, int flags) { return Codecs().decode(bytes, flags); }

bool ImEncode(const std::string& ext, const cv::Mat& image, std::vector<uchar>* out,
              const std::vector<int>& params) {
  return Codecs().encode(ext, image, *out, params);
}

VideoCapture::VideoCapture() { Video().construct(capture()); }
VideoCapture::~VideoCapture() { Video().destroy(capture()); }
bool VideoCapture::Open(int device, int api) { return Video().open_device(capture(), device, api); }
bool VideoCapture::Open(const std::string& name, int api) {
  return Video().open_name(capture(), name, api);
}
bool VideoCapture::IsOpened() const { return Video().is_opened(capture()); }
bool VideoCapture::Read(cv::Mat* image) { return Video().read(capture(), *image); }
double VideoCapture::Get(int property) const { return Video().get(capture(), property); }

}  // namespace mapless::io::lazy
