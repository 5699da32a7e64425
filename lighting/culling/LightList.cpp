#include "lighting/culling/LightList.h"

namespace lighting {

LightList LightList::build(const std::vector<scenes::Light>& sceneLights,
                           const gbuffer::CameraView& view) {
    LightList list;
    list.lights.reserve(sceneLights.size());
    list.lightsExact.reserve(sceneLights.size());
    const glm::dmat3 rotation(view.viewFromWorldExact);
    for (const scenes::Light& light : sceneLights) {
        LightInView<double> exact;
        exact.type = light.type;
        exact.positionView =
            glm::dvec3(view.viewFromWorldExact * glm::dvec4(glm::dvec3(light.positionWorld), 1.0));
        const glm::dvec3 direction = rotation * glm::dvec3(light.directionWorld);
        const double length = glm::length(direction);
        exact.directionView = length > 0.0 ? direction / length : glm::dvec3(0, 0, -1);
        exact.radiance = glm::dvec3(light.color) * double(light.intensity);
        exact.rangeMetres = light.rangeMetres;
        exact.spotInnerCos = light.spotInnerCos;
        exact.spotOuterCos = light.spotOuterCos;
        list.lightsExact.push_back(exact);

        LightInView<float> rounded;
        rounded.type = exact.type;
        rounded.positionView = glm::vec3(exact.positionView);
        rounded.directionView = glm::vec3(exact.directionView);
        rounded.radiance = glm::vec3(exact.radiance);
        rounded.rangeMetres = float(exact.rangeMetres);
        rounded.spotInnerCos = float(exact.spotInnerCos);
        rounded.spotOuterCos = float(exact.spotOuterCos);
        list.lights.push_back(rounded);
    }
    return list;
}

} // namespace lighting
