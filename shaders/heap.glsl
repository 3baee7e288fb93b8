// The per-invocation cut heap of shared/lightcuts.h: K = kHeapSlots entries
// in workgroup shared memory, nothing in global memory while a cut is
// refined. K is the smaller of render.cut_heap and the tree's
// LightTree::cut_heap_capacity(max_cut); a cut that would outgrow it freezes
// its smallest clusters (lc_heap_push), on the CPU reference alike.
//
// Only where a cut is spread over several dispatches (the driver limits how
// long an invocation may loop: lavapipe) is its heap saved to the heap-save
// buffer at the end of a dispatch and restored at the start of the next.
#ifndef LC_HEAP_GLSL
#define LC_HEAP_GLSL

layout(constant_id = kSpecHeapSlots) const uint kHeapSlots = 1u;

layout(std430, binding = kBindingHeapSave) buffer HeapSave { CutEntry heap_save[]; };

// Slot-major, so neighbouring invocations touch neighbouring entries.
shared CutEntry s_heap[kHeapSlots * gl_WorkGroupSize.x];

uint lc_shared_slot(uint slot) { return slot * gl_WorkGroupSize.x + gl_LocalInvocationIndex; }
uint lc_saved_slot(uint slot) { return slot * push.heap_save_stride + gl_GlobalInvocationID.x; }

// Shared slots to global memory and back, around a pause between dispatches.
void lc_heap_save(uint heap_size) {
    for (uint slot = 0u; slot < heap_size; ++slot) heap_save[lc_saved_slot(slot)] = s_heap[lc_shared_slot(slot)];
}

void lc_heap_restore(uint heap_size) {
    for (uint slot = 0u; slot < heap_size; ++slot) s_heap[lc_shared_slot(slot)] = heap_save[lc_saved_slot(slot)];
}

#define HeapEntry CutEntry
#define LC_HEAP_LOAD(i) s_heap[lc_shared_slot(i)]
#define LC_HEAP_STORE(i, e) s_heap[lc_shared_slot(i)] = (e)
#define LC_HEAP_CAPACITY kHeapSlots

#endif
