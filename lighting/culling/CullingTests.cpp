#include "lighting/culling/CullingTests.h"

#include <cmath>

namespace lighting {

ViewFrustum::ViewFrustum(const gbuffer::CameraView& view)
    : mNearMetres(view.nearMetres), mFarMetres(view.farMetres), mProjX(view.clipFromView[0][0]),
      mProjY(view.clipFromView[1][1]) {
    mLengthX = std::sqrt(mProjX * mProjX + 1.0);
    mLengthY = std::sqrt(mProjY * mProjY + 1.0);
}

bool ViewFrustum::mayTouch(const LightSphere& sphere) const {
    if (sphere.unbounded)
        return true;
    const glm::dvec3 c(sphere.centreView);
    const double r = sphere.radius;
    const double depth = -c.z;
    // Every plane moved out by the slack of the farthest point of the sphere from the eye.
    const double reach = r + double(boundSlackMetres(float(glm::length(c) + r)));
    if (depth + reach < mNearMetres * (1.0 - kBoundSlack))
        return false; // wholly nearer than the near plane
    if (depth - reach > mFarMetres * (1.0 + kBoundSlack))
        return false; // wholly beyond the far plane
    // Side planes through the eye: inside when +-p * x + z <= 0 (p = projection scale).
    if ((mProjX * c.x + c.z) / mLengthX > reach || (-mProjX * c.x + c.z) / mLengthX > reach)
        return false;
    if ((mProjY * c.y + c.z) / mLengthY > reach || (-mProjY * c.y + c.z) / mLengthY > reach)
        return false;
    return true;
}

std::vector<uint32_t> ViewFrustum::visibleLights(const std::vector<LightSphere>& spheres,
                                                 bool cull) const {
    std::vector<uint32_t> kept;
    kept.reserve(spheres.size());
    for (uint32_t i = 0; i < uint32_t(spheres.size()); ++i)
        if (!cull || mayTouch(spheres[i]))
            kept.push_back(i);
    return kept;
}

} // namespace lighting
