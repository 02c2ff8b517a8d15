#include <vfield/scene/inputs_hash.h>

#include <vfield/core/field_visitors.h>

namespace vfield {

uint64_t simulationInputsHash(const SimulationSettings& setup, const VolumeSettings& volume)
{
    ContentHash h;
    h.add(std::string("vfield-run 6"));
    hashFields(h, setup, true); // an edited mesh file or elevation model is another simulation
    hashFields(h, volume);
    return h.value();
}

} // namespace vfield
