#include "render/ExrWriter.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfStdIO.h>

#include <stdexcept>
#include <string_view>
#include <variant>

#include "render/AtomicFile.h"

namespace rend::render {

namespace {

/// One channel to write: `components` interleaved floats per pixel in `data`, of which this
/// channel is number `offset`.
struct ChannelSource {
    std::string name;
    const std::vector<float>* data;
    int components;
    int offset;
    Imf::PixelType type;
};

std::vector<ChannelSource> channelSources(const FrameLayers& l) {
    std::vector<ChannelSource> sources;
    auto add = [&](const std::vector<float>& data, int components, std::vector<std::string> names,
                   Imf::PixelType type) {
        if (data.empty()) return;
        if (data.size() != std::size_t(l.width) * l.height * components)
            throw std::invalid_argument("writeExrAtomic: layer " + names[0] +
                                        " does not match the image size");
        for (int k = 0; k < components; ++k)
            sources.push_back({names[k], &data, components, k, type});
    };
    add(l.rgb, 3, {"R", "G", "B"}, Imf::HALF);
    // Depth in full float: half's 11-bit mantissa would band a distance of a few metres.
    add(l.depth, 1, {"Z"}, Imf::FLOAT);
    add(l.normal, 3, {"N.X", "N.Y", "N.Z"}, Imf::HALF);
    add(l.theta, 1, {"theta"}, Imf::HALF);
    return sources;
}

}  // namespace

void writeExrAtomic(const FrameLayers& layers, const std::filesystem::path& path) {
    if (layers.width <= 0 || layers.height <= 0)
        throw std::invalid_argument("writeExrAtomic: image size must be positive");
    const std::vector<ChannelSource> sources = channelSources(layers);
    const std::size_t pixels = std::size_t(layers.width) * layers.height;
    Imf::Header header(layers.width, layers.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    // OpenEXR converts while it writes, so each channel gets a packed buffer of its own type.
    std::vector<std::variant<std::vector<half>, std::vector<float>>> planes;
    planes.reserve(sources.size());
    Imf::FrameBuffer frame;
    for (const ChannelSource& s : sources) {
        header.channels().insert(s.name, Imf::Channel(s.type));
        char* base;
        std::size_t size;
        if (s.type == Imf::HALF) {
            auto& plane = std::get<0>(planes.emplace_back(std::vector<half>(pixels)));
            for (std::size_t i = 0; i < pixels; ++i)
                plane[i] = half((*s.data)[i * s.components + s.offset]);
            base = reinterpret_cast<char*>(plane.data());
            size = sizeof(half);
        } else {
            auto& plane = std::get<1>(planes.emplace_back(std::vector<float>(pixels)));
            for (std::size_t i = 0; i < pixels; ++i)
                plane[i] = (*s.data)[i * s.components + s.offset];
            base = reinterpret_cast<char*>(plane.data());
            size = sizeof(float);
        }
        frame.insert(s.name, Imf::Slice(s.type, base, size, size * layers.width));
    }
    // Encoded in memory, then written like every other output: a reader never sees half a file.
    Imf::StdOSStream stream;
    {
        Imf::OutputFile file(stream, header);
        file.setFrameBuffer(frame);
        file.writePixels(layers.height);
    }
    writeFileAtomic(path, stream.str());
}

ExrChannels readExr(const std::filesystem::path& path) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        ExrChannels result;
        result.width = window.max.x - window.min.x + 1;
        result.height = window.max.y - window.min.y + 1;
        const std::size_t pixels = std::size_t(result.width) * result.height;
        Imf::FrameBuffer frame;
        const Imf::ChannelList& list = file.header().channels();
        for (auto it = list.begin(); it != list.end(); ++it) {
            auto& plane = result.channels[it.name()];
            plane.resize(pixels);
            // Slices address pixel (x, y) at base + x * xStride + y * yStride, data window
            // included, so the base is shifted back to the window's corner.
            char* base =
                reinterpret_cast<char*>(plane.data()) -
                (std::ptrdiff_t(window.min.x) + std::ptrdiff_t(window.min.y) * result.width) *
                    std::ptrdiff_t(sizeof(float));
            frame.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float),
                                               sizeof(float) * std::size_t(result.width)));
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        return result;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read " + path.string() + ": " + e.what());
    }
}

}  // namespace rend::render
