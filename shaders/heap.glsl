// The per-invocation cut heap of lc_shared/lightcuts.h: K = kHeapSlots entries,
// an array of the invocation's own (kHeapPrivate, the default) or in
// workgroup shared memory. K is the smaller of render.cut_heap and the
// tree's LightTree::cut_heap_capacity(max_cut); a cut that would outgrow it
// freezes its smallest clusters (lc_heap_push), on the CPU reference alike.
//
// Private memory measured faster on both kinds of device: llvmpipe turns
// every shared-memory access whose address differs between lanes into a
// loop over the lanes, and such loops fell from 26% to 2.7% of the shader's
// profile samples with the heap in private memory (lavapipe's shading 0.78-
// 0.82 s instead of 0.93-1.42 s on the room, docs/results/lavapipe.md,
// §10); on an H200 K = 64 slots in shared memory left room for a fifth of
// the invocations a multiprocessor runs, 246 ms of GPU time against 80 ms
// private (docs/results/gpu.md).
//
// Only where a cut is spread over several dispatches (the driver limits how
// long an invocation may loop, as lavapipe does, or a GPU's slow tiles
// split the work) is its heap saved to the heap-save buffer at the end of a
// dispatch and restored at the start of the next.
#ifndef LC_HEAP_GLSL
#define LC_HEAP_GLSL

#extension GL_EXT_control_flow_attributes : require

// The entry and the field that orders the heap: CutEntry by its error, or
// what the includer defines first (quadcuts.comp: QuadCutEntry by its key).
#ifndef LC_HEAP_ENTRY
#define LC_HEAP_ENTRY CutEntry
#endif
#ifndef LC_HEAP_ORDER
#define LC_HEAP_ORDER error
#endif

layout(constant_id = kSpecHeapSlots) const uint kHeapSlots = 1u;
layout(constant_id = kSpecHeapPrivate) const bool kHeapPrivate = false;

layout(std430, binding = kBindingHeapSave) buffer HeapSave { LC_HEAP_ENTRY heap_save[]; };

// Slot-major, so neighbouring invocations touch neighbouring entries. The
// array that is not used has one entry.
shared LC_HEAP_ENTRY s_heap[kHeapPrivate ? 1u : kHeapSlots * gl_WorkGroupSize.x];
LC_HEAP_ENTRY p_heap[kHeapPrivate ? kHeapSlots : 1u];

uint lc_shared_slot(uint slot) { return slot * gl_WorkGroupSize.x + gl_LocalInvocationIndex; }
uint lc_saved_slot(uint slot) { return slot * push.heap_save_stride + gl_GlobalInvocationID.x; }

LC_HEAP_ENTRY lc_heap_load(uint slot) { return kHeapPrivate ? p_heap[slot] : s_heap[lc_shared_slot(slot)]; }

void lc_heap_store(uint slot, LC_HEAP_ENTRY e) {
    if (kHeapPrivate) {
        p_heap[slot] = e;
    } else {
        s_heap[lc_shared_slot(slot)] = e;
    }
}

// The slots to global memory and back, around a pause between dispatches.
void lc_heap_save(uint heap_size) {
    for (uint slot = 0u; slot < heap_size; ++slot) heap_save[lc_saved_slot(slot)] = lc_heap_load(slot);
}

void lc_heap_restore(uint heap_size) {
    for (uint slot = 0u; slot < heap_size; ++slot) lc_heap_store(slot, heap_save[lc_saved_slot(slot)]);
}

// lc_heap_smallest on a full heap, the only heap it is asked about
// (lc_heap_push: from = K/2, to = K): for K up to 256 (a quad's heap at
// the default cut_heap 64) a loop the compiler unrolls once K is
// specialized, so that each slot's index is the same constant in every lane
// (llvmpipe reads a private array at an index that may differ between lanes
// one lane at a time, at a constant index all the lanes at once; and it ends
// an invocation's loops after 65535 iterations in all, which a quad's scans
// of 128 slots a freeze had reached at the room's deepest cuts); above that
// lc_shared/lightcuts.h's loop. Same slots, same order, same answer.
uint lc_heap_smallest_scan(uint from, uint to, float bound);  // lc_shared/lightcuts.h

uint lc_heap_smallest_full(uint from, uint to, float bound) {
    if (kHeapSlots > 256u) return lc_heap_smallest_scan(from, to, bound);
    uint smallest = kInvalidIndex;
    float smallest_error = bound;
    [[unroll]] for (uint i = kHeapSlots / 2u; i < kHeapSlots; ++i) {
        float error = lc_heap_load(i).LC_HEAP_ORDER;
        bool smaller = error < smallest_error; // false for a NaN error, as in the loop
        smallest = smaller ? i : smallest;
        smallest_error = smaller ? error : smallest_error;
    }
    return smallest;
}

#define HeapEntry LC_HEAP_ENTRY
#define LC_HEAP_SMALLEST(from, to, bound) lc_heap_smallest_full(from, to, bound)
#define LC_HEAP_LOAD(i) lc_heap_load(i)
#define LC_HEAP_STORE(i, e) lc_heap_store(i, e)
#define LC_HEAP_CAPACITY kHeapSlots

#endif
