// The buffers the kernels read and write and the one descriptor set that
// binds them (shaders/bindings.glsl): the scene's arrays, uploaded once, and
// the per-tile buffers, sized for the largest tile the device's buffer
// limits allow. Also the pipeline layout every kernel shares.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bindings.glsl"
#include "kernels.h"
#include "lightcuts/render.h"
#include "shading_method.h"
#include "vk_commands.h"
#include "vk_context.h"

namespace lc::vk {

// Size of the per-tile buffers.
struct TileLayout {
    std::uint32_t max_pixels = 0;   // largest tile the buffers hold
    std::uint32_t invocations = 0;  // max_pixels rounded up to whole workgroups
};

class GpuResources {
public:
    // Uploads `scene` (scene_arrays() order, then the frame constants:
    // bindings kBindingBvhNodes .. kBindingFrame), sizes and creates the per-tile buffers for
    // `method` and an image of `image_pixels` (tiles of at most
    // `max_tile_pixels`, 0: no cap), and binds everything. Throws naming
    // the buffer, its size and the device limit when something cannot fit.
    // Large scene arrays that own whole pages of host memory are used in
    // place on a CPU device that can import host memory (`host_import`).
    // A scene array larger than one buffer may be (or than `split_bytes`, if
    // not 0) is split into chunks of 2^k elements: windows of one buffer
    // where the array fits one allocation and not `chunk_buffers`, else
    // each its own buffer.
    // `texel_reads`: let the kernels read the BVH nodes, triangles, lights
    // and light-tree nodes through texel views, where the device allows
    // (texel_reads() says whether it did).
    GpuResources(const Context& ctx, Submitter& submitter, const std::vector<SceneArray>& scene,
                 const ShadingMethod& method, std::uint64_t image_pixels,
                 std::uint32_t max_tile_pixels, std::uint64_t split_bytes = 0,
                 bool texel_reads = false, bool chunk_buffers = false, bool host_import = true);

    const TileLayout& tiles() const { return tiles_; }
    // How the scene arrays were split, for the kernels' specialization.
    const SceneChunks& chunks() const { return chunks_; }
    // The texel views cover the four arrays (kBindingBvhNodeTexels ..): the
    // kernels may read them there.
    bool texel_reads() const { return texel_reads_; }
    // Chunks of the scene array at `binding` (1 where it fits one buffer),
    // and the buffers that hold them (1, or one per chunk).
    std::size_t chunk_count(std::uint32_t binding) const { return chunk_counts_[binding]; }
    std::size_t chunk_buffer_count(std::uint32_t binding) const { return scene_[binding].size(); }
    // The scene array at `binding` is read where it is in host memory.
    bool imported(std::uint32_t binding) const { return imported_[binding]; }
    VkDescriptorSet descriptor_set() const { return descriptor_set_; }
    VkPipelineLayout pipeline_layout() const { return pipeline_layout_.get(); }

    // Per-tile outputs: zeroed before a tile's first sample.
    const Buffer& radiance() const { return tile_[kRadiance]; }
    const Buffer& pixel_stats() const { return tile_[kPixelStats]; }
    // Device memory the host cannot map: the last pass of a tile copies the
    // outputs to these read-back buffers (empty otherwise).
    const Buffer& radiance_readback() const { return radiance_readback_; }
    const Buffer& stats_readback() const { return stats_readback_; }
    bool needs_readback_copies() const { return radiance_readback_.get() != VK_NULL_HANDLE; }
    // Where the host reads a tile's outputs once its last pass has finished.
    const float* radiance_sums() const;
    const gpu::PixelStats* pixel_stats_sums() const;

    // Every buffer created, in creation order (RenderStats::buffer_bytes).
    const std::vector<std::pair<std::string, std::uint64_t>>& buffer_bytes() const {
        return buffer_bytes_;
    }

private:
    // Per-tile buffers, in binding order from kBindingGBuffer.
    enum TileIndex { kGBuffer, kRadiance, kPixelStats, kHeapSave, kCutState, kTileBufferCount };

    Buffer storage_buffer(const std::string& name, VkDeviceSize bytes, MemoryUse use,
                          VkBufferUsageFlags extra_usage = 0);
    void check_fits(const std::string& name, VkDeviceSize bytes) const;
    void upload(const std::string& name, const void* data, VkDeviceSize bytes, Buffer& buffer,
                VkDeviceSize offset = 0);
    std::vector<Buffer> upload_chunks(const SceneArray& array, std::uint32_t binding);
    void upload_scene(const std::vector<SceneArray>& scene);
    void create_chunk_table();
    bool texel_views_fit() const;
    void create_texel_views();
    std::vector<TileBuffer> tile_buffers(const ShadingMethod& method) const;
    void fit_tiles(const std::vector<TileBuffer>& buffers, std::uint64_t image_pixels,
                   std::uint32_t max_tile_pixels);
    void create_tile_buffers(const std::vector<TileBuffer>& buffers);
    void create_descriptors();
    void create_pipeline_layout();

    const Context& ctx_;
    Submitter& submitter_;
    VkDeviceSize max_buffer_ = 0;  // min(maxStorageBufferRange, maxMemoryAllocationSize)
    VkDeviceSize split_bytes_ = 0;  // a smaller chunk size forced by Tuning (0: none)
    bool chunk_buffers_ = false;    // every chunk its own buffer (Tuning::chunk_buffers)
    bool host_import_ = true;       // Tuning::host_import
    SceneChunks chunks_;
    bool texel_reads_ = false;
    TileLayout tiles_;
    std::vector<std::pair<std::string, std::uint64_t>> buffer_bytes_;

    // Destroyed in reverse: layouts and descriptors before the buffers.
    // Bindings kBindingBvhNodes .. kBindingFrame, each one buffer (whose
    // windows the chunks of a split array are) or one buffer per chunk;
    // the binding holds chunk 0.
    std::vector<std::vector<Buffer>> scene_;
    // Per binding (scene arrays, then the frame constants): chunks, and the
    // bytes of chunk 0 (the range the binding sees).
    std::vector<std::uint64_t> chunk_counts_;
    std::vector<VkDeviceSize> first_chunk_bytes_;
    std::vector<bool> imported_;
    Buffer chunk_table_;                        // binding kBindingChunkTable
    // Bindings kBindingBvhNodeTexels ..: over the whole array where
    // texel_reads_, else over its first texel (the kernels do not read them,
    // but every binding needs a valid descriptor).
    std::vector<BufferView> texel_views_;
    Buffer tile_[kTileBufferCount];             // bindings kBindingGBuffer ..
    Buffer radiance_readback_, stats_readback_;
    DescriptorSetLayout set_layout_;
    DescriptorPool descriptor_pool_;
    VkDescriptorSet descriptor_set_ = VK_NULL_HANDLE;
    PipelineLayout pipeline_layout_;
};

}  // namespace lc::vk
