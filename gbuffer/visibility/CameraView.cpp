#include "gbuffer/visibility/CameraView.h"

#include <glm/gtc/matrix_transform.hpp>

namespace gbuffer {

CameraView CameraView::fromCamera(const scenes::Camera& camera, int width, int height,
                                  DepthConvention convention, bool infiniteFar,
                                  glm::dvec2 pixelOffset) {
    CameraView view;
    view.pixelOffset = pixelOffset;
    view.infiniteFar = infiniteFar;
    view.depthConvention = convention;
    view.width = width;
    view.height = height;
    view.nearMetres = camera.nearMetres;
    view.farMetres = camera.farMetres;
    const double aspect = double(width) / double(height);
    // Built in double, then rounded: the float matrices and the exact ones describe one camera.
    // From the camera's basis (Scene.h), never from eye + forward, which rounds to eye far out.
    view.viewFromWorldExact = camera.viewFromWorldExact();
    glm::dmat4 clipFromViewExact =
        glm::perspectiveRH_ZO(double(camera.verticalFovRadians), aspect, double(camera.nearMetres),
                              double(camera.farMetres));
    if (infiniteFar) {
        // The limit f -> infinity of the zero-to-one perspective: z_clip = d - n, w = d, so
        // z_ndc = 1 - n / d (far plane at infinity, no far clipping).
        clipFromViewExact[2][2] = -1.0;
        clipFromViewExact[3][2] = -double(camera.nearMetres);
    }
    if (convention == DepthConvention::Reversed) {
        // z' = w - z maps [0, w] onto [w, 0]: near -> 1, far -> 0.
        glm::dmat4 reverse(1.0);
        reverse[2][2] = -1.0;
        reverse[3][2] = 1.0;
        clipFromViewExact = reverse * clipFromViewExact;
    }
    if (pixelOffset != glm::dvec2(0.0)) {
        // The point that lands on a pixel's centre is the one that was (dx, dy) pixels away
        // from it: translate NDC by minus the offset, in clip space (times w).
        glm::dmat4 shift(1.0);
        shift[3][0] = -2.0 * pixelOffset.x / double(width);
        shift[3][1] = 2.0 * pixelOffset.y / double(height);
        clipFromViewExact = shift * clipFromViewExact;
    }
    view.viewFromClipExact = glm::inverse(clipFromViewExact);
    view.viewFromWorld = glm::mat4(view.viewFromWorldExact);
    view.clipFromView = glm::mat4(clipFromViewExact);
    view.viewFromClip = glm::mat4(view.viewFromClipExact);
    view.viewFromWorldNormal = glm::mat3(view.viewFromWorld);
    return view;
}

} // namespace gbuffer
