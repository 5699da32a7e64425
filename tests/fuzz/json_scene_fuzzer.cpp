// libFuzzer target: the JSON scene reader (scenes::loadScene on a .json file), with and without a
// light count from the request. Only SceneError may leave the reader.
#include <cstddef>
#include <cstdint>

#include "FuzzInput.h"
#include "scenes/SceneLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::filesystem::path path = fuzz::writeInput(data, size, "input.json");
    scenes::SceneRequest request;
    // The last byte, when odd, asks for generated lights as the CLI does.
    if (size > 0 && (data[size - 1] & 1))
        request.lightCount = 16;
    try {
        const scenes::Scene scene = scenes::loadScene(path.string(), request);
        (void)scene.triangleCount();
    } catch (const scenes::SceneError&) {
    }
    return 0;
}
