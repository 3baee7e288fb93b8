// A light-tree node decoded from the 16-byte words the kernels read (types.h,
// "A LightNode as the kernels read it"). The includer defines
// LC_LIGHT_NODE_WORD(k), word k of the node array, and LC_LIGHT_NODE_FRAME,
// the LightNodeFrame. Compiles as GLSL and as C++ (inside a kernel struct,
// like trace.h), so the host's packing, the CPU path and the Vulkan kernels
// decode every node with the same operations.

LightNode lc_light_node(uint i) {
    uvec4 a = LC_LIGHT_NODE_WORD(kLightNodeWords * i);
    uvec4 b = LC_LIGHT_NODE_WORD(kLightNodeWords * i + 1u);
    uint type = (b.x >> kLightNodeTypeShift) & kLightNodeTypeBits;
    uint left = b.x & kLightNodeNoChild;
    uint o = 3u * type;
    LightNode n;
    // plane * step is exact (a power of two times at most 65535), so a
    // fused multiply-add gives the same sum as the host, which checked the
    // rounding of each plane with it (light_tree.cpp, pack_light_nodes).
    n.min_x = LC_LIGHT_NODE_FRAME.origin[o] + float(b.y & 0xFFFFu) * LC_LIGHT_NODE_FRAME.step[o];
    n.min_y = LC_LIGHT_NODE_FRAME.origin[o + 1u] + float(b.y >> 16u) * LC_LIGHT_NODE_FRAME.step[o + 1u];
    n.min_z = LC_LIGHT_NODE_FRAME.origin[o + 2u] + float(b.z & 0xFFFFu) * LC_LIGHT_NODE_FRAME.step[o + 2u];
    n.max_x = LC_LIGHT_NODE_FRAME.origin[o] + float(b.z >> 16u) * LC_LIGHT_NODE_FRAME.step[o];
    n.max_y = LC_LIGHT_NODE_FRAME.origin[o + 1u] + float(b.w & 0xFFFFu) * LC_LIGHT_NODE_FRAME.step[o + 1u];
    n.max_z = LC_LIGHT_NODE_FRAME.origin[o + 2u] + float(b.w >> 16u) * LC_LIGHT_NODE_FRAME.step[o + 2u];
    n.intensity_r = uintBitsToFloat(a.x);
    n.intensity_g = uintBitsToFloat(a.y);
    n.intensity_b = uintBitsToFloat(a.z);
    n.rep_light = a.w;
    n.left = left == kLightNodeNoChild ? kInvalidIndex : left;
    n.flags = (type << kNodeTypeShift) | (left == kLightNodeNoChild ? kNodeLeaf : 0u) |
              ((b.x & kLightNodeRepFromRight) != 0u ? kNodeRepFromRight : 0u) |
              ((b.x & kLightNodeTwoSided) != 0u ? kNodeTwoSided : 0u);
    if (i >= LC_LIGHT_NODE_FRAME.cone_base) {
        uvec4 c = LC_LIGHT_NODE_WORD(kLightNodeWords * LC_LIGHT_NODE_FRAME.node_count + (i - LC_LIGHT_NODE_FRAME.cone_base));
        n.axis_oct = c.x;
        n.cos_theta_o = uintBitsToFloat(c.y);
        n.cos_theta_e = uintBitsToFloat(c.z);
        n.falloff_width = uintBitsToFloat(c.w);
    } else {
        n.axis_oct = LC_LIGHT_NODE_FRAME.everywhere_axis_oct;
        n.cos_theta_o = LC_LIGHT_NODE_FRAME.everywhere_cos_theta_o;
        n.cos_theta_e = LC_LIGHT_NODE_FRAME.everywhere_cos_theta_e;
        n.falloff_width = LC_LIGHT_NODE_FRAME.everywhere_falloff_width;
    }
    return n;
}
