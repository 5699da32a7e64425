// libFuzzer target: the glTF loader (scenes::loadGltf) on .gltf JSON and .glb binary input (the
// loader tells them apart by the GLB magic, as it does for real files). The only acceptable
// outcome besides a Scene is a SceneError: any other exception, a crash or a sanitizer report is
// a finding.
#include <cstddef>
#include <cstdint>

#include "FuzzInput.h"
#include "scenes/SceneLoader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::filesystem::path path = fuzz::writeInput(data, size, "input.gltf");
    try {
        const scenes::Scene scene = scenes::loadGltf(path);
        (void)scene.triangleCount();
    } catch (const scenes::SceneError&) {
    }
    return 0;
}
