#include "app/stability.h"

namespace rastray::stability {

void appendLayerCases(std::vector<Case>& cases) { (void)cases; }

}  // namespace rastray::stability
