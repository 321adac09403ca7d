#include "render/Image.h"

#include <zlib.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <system_error>

#include "render/AtomicFile.h"

namespace {

// The PNG's deflate stream from zlib rather than stb's own compressor (stb_image_write's
// STBIW_ZLIB_COMPRESS): at zlib's default level, as libpng writes, a final foil frame (960 x 540)
// took 31 ms and 124 KB against stb's 48 ms and 162 KB. stb frees the buffer with free().
unsigned char* deflateWithZlib(unsigned char* data, int size, int* written, int /*stbLevel*/) {
    uLongf bound = compressBound(uLong(size));
    auto* out = static_cast<unsigned char*>(std::malloc(bound));
    if (out == nullptr) return nullptr;
    if (compress2(out, &bound, data, uLong(size), Z_DEFAULT_COMPRESSION) != Z_OK) {
        std::free(out);
        return nullptr;  // stb then fails the write: "cannot encode PNG"
    }
    *written = int(bound);
    return out;
}

}  // namespace

// stb is third-party C; its warnings under -Wextra -Wpedantic are not ours to fix.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wunused-function"
#define STBIW_ZLIB_COMPRESS deflateWithZlib
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>
#pragma GCC diagnostic pop

namespace rend::render {

namespace {

void checkShape(const Image& image) {
    const auto expected = static_cast<std::size_t>(image.width) * image.height * 3;
    if (image.width <= 0 || image.height <= 0 || image.rgb.size() != expected)
        throw std::runtime_error("writePngAtomic: image size does not match its pixel buffer");
}

int channelDifference(const Image& a, const Image& b, std::size_t pixel) {
    int worst = 0;
    for (std::size_t c = 0; c < 3; ++c) {
        const int d = std::abs(int(a.rgb[pixel * 3 + c]) - int(b.rgb[pixel * 3 + c]));
        worst = std::max(worst, d);
    }
    return worst;
}

void markPixel(Image& diff, std::size_t pixel, bool failing) {
    std::uint8_t* p = &diff.rgb[pixel * 3];
    if (failing) {
        p[0] = 255;
        p[1] = 0;
        p[2] = 0;
        return;
    }
    // Darkening the passing pixels keeps the picture recognisable while red failures pop out.
    for (int c = 0; c < 3; ++c) p[c] = static_cast<std::uint8_t>(p[c] * 3 / 10);
}

}  // namespace

void writePngAtomic(const Image& image, const std::filesystem::path& path) {
    checkShape(image);
    // Encoded in memory, then written with every write checked: stb's own file writer ignores
    // fwrite's and fclose's errors, which leaves truncated PNGs behind on a full disk.
    std::string png;
    const auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), size);
    };
    if (!stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(),
                                image.width * 3))
        throw std::runtime_error("cannot encode PNG " + path.string());
    writeFileAtomic(path, png);
}

Image readPng(const std::filesystem::path& path) {
    int w = 0;
    int h = 0;
    int channels = 0;
    std::uint8_t* data = stbi_load(path.c_str(), &w, &h, &channels, 3);
    if (!data) {
        throw std::runtime_error("cannot read PNG " + path.string() + ": " + stbi_failure_reason());
    }
    Image image{w, h, std::vector<std::uint8_t>(data, data + std::size_t(w) * h * 3)};
    stbi_image_free(data);
    return image;
}

ImageDiff compareImages(const Image& reference, const Image& actual, int tolerance) {
    ImageDiff result;
    result.diff = reference;
    if (reference.width != actual.width || reference.height != actual.height ||
        reference.rgb.size() != actual.rgb.size()) {
        return result;  // defaults already say "everything fails"
    }
    const std::size_t pixels = reference.rgb.size() / 3;
    std::size_t failing = 0;
    int worst = 0;
    for (std::size_t i = 0; i < pixels; ++i) {
        const int d = channelDifference(reference, actual, i);
        worst = std::max(worst, d);
        const bool fails = d > tolerance;
        failing += fails ? 1 : 0;
        markPixel(result.diff, i, fails);
    }
    result.failingFraction = pixels > 0 ? double(failing) / double(pixels) : 0.0;
    result.maxDifference = worst;
    return result;
}

}  // namespace rend::render
