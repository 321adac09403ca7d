#include "render/Versions.h"

#include <assimp/version.h>
#include <embree3/rtcore.h>
#include <openvdb/openvdb.h>
#include <zlib.h>

#include <stdexcept>

#include "render/OsmesaRenderer.h"

namespace rend::render {

namespace {

std::string embreeVersion() {
    // Asking a live device reports the library actually loaded, not the header we compiled
    // against.
    RTCDevice device = rtcNewDevice(nullptr);
    if (!device) return "unavailable";
    const auto part = [&](RTCDeviceProperty p) {
        return std::to_string(rtcGetDeviceProperty(device, p));
    };
    std::string version = part(RTC_DEVICE_PROPERTY_VERSION_MAJOR) + "." +
                          part(RTC_DEVICE_PROPERTY_VERSION_MINOR) + "." +
                          part(RTC_DEVICE_PROPERTY_VERSION_PATCH);
    rtcReleaseDevice(device);
    return version;
}

std::string openvdbVersion() {
    // OpenVDB has no run-time version query; initialising it at least proves the library
    // linked and loads.
    openvdb::initialize();
    return openvdb::getLibraryVersionString();
}

std::string assimpVersion() {
    return std::to_string(aiGetVersionMajor()) + "." + std::to_string(aiGetVersionMinor()) + "." +
           std::to_string(aiGetVersionPatch());
}

std::string osmesaVersion() {
    try {
        OsmesaRenderer renderer;
        return renderer.glDescription();
    } catch (const std::exception& e) {
        return std::string("unavailable: ") + e.what();
    }
}

}  // namespace

std::vector<std::pair<std::string, std::string>> renderLibraryVersions() {
    return {
        {"Embree", embreeVersion()},
        {"OpenVDB", openvdbVersion()},
        {"assimp", assimpVersion()},
        {"OSMesa", osmesaVersion()},
        {"stb", "stb_image_write (libstb-dev)"},
        {"zlib", zlibVersion()},
    };
}

}  // namespace rend::render
