#pragma once
// Linear RGB images and their files: a tone-mapped 8-bit PNG (libpng) and a linear 32-bit float
// EXR (OpenEXR, ZIP-compressed scanlines). Tone mapping: exposure 2^EV,
// the ACES filmic fit of Narkowicz 2015 ("ACES filmic tone mapping curve"), then the sRGB
// transfer function (IEC 61966-2-1).

#include "core/rgb.h"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace lamina {

struct Image {
    int width = 0, height = 0;
    std::vector<Rgbf> pixels;  ///< row-major, row 0 at the top, linear radiance

    Image() = default;
    Image(int w, int h, Rgbf fill = Rgbf(0.f))
        : width(w), height(h), pixels(std::size_t(w) * h, fill) {}
    Rgbf& at(int x, int y) { return pixels[std::size_t(y) * width + x]; }
    const Rgbf& at(int x, int y) const { return pixels[std::size_t(y) * width + x]; }
};

/// The exposures --exposure takes, in stops: ±40 is a factor of 10¹², past any image's range.
inline constexpr double kMaxExposureStops = 40;

/// 8-bit sRGB of a linear value after exposure and the ACES fit (any input: NaN and ∞ too).
std::uint8_t tone_map_channel(double linear, double exposure_ev);

/// Writes `image` tone-mapped (exposure_ev) as an 8-bit RGB PNG; an already display-referred
/// image (a contact sheet) uses `tone_map = false` (values in [0, 1] are sRGB-encoded directly).
void write_png(const std::filesystem::path& path, const Image& image, double exposure_ev = 0,
               bool tone_map = true);

/// Writes the linear image as an RGB float EXR (OpenEXR), atomically.
void write_exr(const std::filesystem::path& path, const Image& image);

/// Reads the R, G, B channels of an EXR file as float (InputError naming the file otherwise).
Image read_exr(const std::filesystem::path& path);

}  // namespace lamina
