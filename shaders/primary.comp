// Camera rays: one sample (PushConstants.sample_index) of every pixel of the
// tile, traced to the closest hit and stored as a G-buffer texel for the
// shading kernels.
#version 460
#extension GL_GOOGLE_include_directive : require

#include "kernel.glsl"

void main() {
    uint i = lc_tile_pixel();
    if (i == kInvalidIndex) return;
    uint x = lc_tile_x(i);
    uint y = lc_tile_y(i);

    SurfacePoint sp;
    GBufferTexel g;
    vec3 seen;
    bool hit = lc_camera_sample(frame, x, y, push.sample_index, sp, seen);
    // What the camera sees directly (emission, environment) starts the
    // sample's sum; shading adds the reflected light.
    lc_accumulate(i, seen);
    if (!hit) {
        g.px = 0.0f; g.py = 0.0f; g.pz = 0.0f;
        g.nx = 0.0f; g.ny = 0.0f; g.nz = 0.0f;
        g.wo_x = 0.0f; g.wo_y = 0.0f; g.wo_z = 0.0f;
        g.material = kInvalidIndex;
        g.u = 0.0f;
        g.v = 0.0f;
        g.footprint_major_u = 0.0f; g.footprint_major_v = 0.0f;
        g.footprint_minor_u = 0.0f; g.footprint_minor_v = 0.0f;
    } else {
        g.px = sp.p.x; g.py = sp.p.y; g.pz = sp.p.z;
        g.nx = sp.n.x; g.ny = sp.n.y; g.nz = sp.n.z;
        g.wo_x = sp.wo.x; g.wo_y = sp.wo.y; g.wo_z = sp.wo.z;
        g.material = sp.material;
        g.u = sp.uv.x;
        g.v = sp.uv.y;
        g.footprint_major_u = sp.footprint.x; g.footprint_major_v = sp.footprint.y;
        g.footprint_minor_u = sp.footprint.z; g.footprint_minor_v = sp.footprint.w;
    }
    gbuffer[i] = g;
    if (lc_loops_were_cut_short()) pixel_stats[i].flags |= kPixelLoopLimit;
}
