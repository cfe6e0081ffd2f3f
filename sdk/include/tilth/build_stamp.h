// What a compilation was built with, beyond the plugin ABI version. The interface between
// the runtime and a plugin passes std::string, std::function, nlohmann::json and cv::Mat,
// which the standard library, nlohmann-json and OpenCV lay out; the runtime refuses a
// plugin whose standard library or libraries differ from its own, and names the
// difference. A different compiler on the same libraries is noted, not refused.
#pragma once

#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core/version.hpp>

namespace tilth {

struct BuildStamp {
  const char* compiler;          // family and major version: "GCC 12", "Clang 14"
  const char* standard_library;  // "libstdc++ 12, C++11 ABI", "libc++ 15000"
  const char* opencv;            // major.minor, as its shared libraries' names: "4.6"
  const char* json;              // nlohmann-json's version, which names its ABI namespace
};

#define TILTH_STAMP_TEXT_(x) #x
#define TILTH_STAMP_TEXT(x) TILTH_STAMP_TEXT_(x)

#if defined(__clang__)
#define TILTH_STAMP_COMPILER "Clang " TILTH_STAMP_TEXT(__clang_major__)
#elif defined(__GNUC__)
#define TILTH_STAMP_COMPILER "GCC " TILTH_STAMP_TEXT(__GNUC__)
#else
#define TILTH_STAMP_COMPILER "an unknown compiler"
#endif

#if defined(_LIBCPP_VERSION)
#define TILTH_STAMP_STANDARD_LIBRARY "libc++ " TILTH_STAMP_TEXT(_LIBCPP_VERSION)
#elif defined(_GLIBCXX_RELEASE) && _GLIBCXX_USE_CXX11_ABI
#define TILTH_STAMP_STANDARD_LIBRARY "libstdc++ " TILTH_STAMP_TEXT(_GLIBCXX_RELEASE) ", C++11 ABI"
#elif defined(_GLIBCXX_RELEASE)
#define TILTH_STAMP_STANDARD_LIBRARY "libstdc++ " TILTH_STAMP_TEXT(_GLIBCXX_RELEASE) ", old ABI"
#else
#define TILTH_STAMP_STANDARD_LIBRARY "an unknown standard library"
#endif

// The stamp of the compilation that includes this header: a plugin's, in TILTH_PLUGIN,
// and the runtime's own.
inline constexpr BuildStamp kThisBuild{
    TILTH_STAMP_COMPILER, TILTH_STAMP_STANDARD_LIBRARY,
    TILTH_STAMP_TEXT(CV_VERSION_MAJOR) "." TILTH_STAMP_TEXT(CV_VERSION_MINOR),
    TILTH_STAMP_TEXT(NLOHMANN_JSON_VERSION_MAJOR) "." TILTH_STAMP_TEXT(
        NLOHMANN_JSON_VERSION_MINOR) "." TILTH_STAMP_TEXT(NLOHMANN_JSON_VERSION_PATCH)};

// "GCC 12, libstdc++ 12, C++11 ABI, OpenCV 4.6, nlohmann-json 3.11.2"; "?" for a field not set.
std::string describe(const BuildStamp& stamp);

}  // namespace tilth
