// Which renderer runs a render (DeviceChoice, include/lightcuts/render.h).
// Compiled into lc_vulkan, the one library that sees both renderers.
#include <stdexcept>
#include <string>

#include "lightcuts/render.h"

namespace lc {

namespace {

void say(const DeviceChoice& choice, const std::string& line) {
    if (choice.note) choice.note(line);
}

}  // namespace

std::string device_problem(std::string_view device) {
    if (device == "auto" || device == "cpu" || device == "vulkan") return "";
    return "must be \"auto\", \"cpu\" or \"vulkan\", got \"" + std::string(device) + "\"";
}

std::string vulkan_options_problem(const DeviceChoice& choice, std::string_view method) {
    const char* option = choice.vulkan.validation ? "--validation" : !choice.vulkan.gpu.empty() ? "--gpu" : nullptr;
    if (option == nullptr) return "";
    if (choice.device == "cpu") return std::string(option) + " is for Vulkan renders, and device \"cpu\" does not use Vulkan";
    if (choice.device == "auto" && method == "path")
        return std::string(option) + " is for Vulkan renders, and method path (the path tracer) runs on the CPU only";
    return "";
}

RenderResult render(const PreparedScene& prepared, const RenderOptions& options, const DeviceChoice& choice) {
    const std::string problem = device_problem(choice.device);
    if (!problem.empty()) throw std::invalid_argument("device " + problem);
    const std::string vulkan_problem = vulkan_options_problem(choice, options.method);
    if (!vulkan_problem.empty()) throw std::invalid_argument(vulkan_problem);
    if (choice.device == "cpu") return render_cpu(prepared, options);
    if (choice.device == "vulkan") return render_vulkan(prepared, options, choice.vulkan);

    // auto: the path tracer runs on the CPU only. Otherwise a named device
    // is always tried, and only real GPU hardware beats the CPU path
    // (lavapipe on the same cores is several times slower).
    if (options.method == "path") return render_cpu(prepared, options);
    const std::string on_cpu =
        std::string("rendering on the CPU") + (choice.vulkan.validation ? ", which --validation does not check" : "");
    if (choice.vulkan.gpu.empty()) {
        const GpuProbe probe = choice.devices.valid() ? choice.devices.get() : probe_gpus();
        const VulkanDevices& found = probe.devices;
        if (!found.hardware) {
            say(choice, probe.skipped ? "no GPU on this machine (no device file in /dev that a GPU's driver uses); " + on_cpu
                        : found.names.empty()
                            ? "no Vulkan device; " + on_cpu
                            : "only a software Vulkan device is present; " + on_cpu +
                                  " (device \"vulkan\" uses it anyway)");
            return render_cpu(prepared, options);
        }
    }
    try {
        return render_vulkan(prepared, options, choice.vulkan);
    } catch (const NoVulkanDevice& e) {
        say(choice, std::string(e.what()) + "; " + on_cpu);
        return render_cpu(prepared, options);
    } catch (const std::invalid_argument& e) {
        // The options are valid (render_vulkan checks them first, as the
        // CPU would), so what the device refused is cut_sharing "quad" or
        // "octet".
        if (!(method_selects_cuts(options.method) && (options.cut_sharing == "quad" || options.cut_sharing == "octet")))
            throw;
        say(choice, std::string(e.what()) + "; " + on_cpu);
        return render_cpu(prepared, options);
    }
}

}  // namespace lc
