#include "app/stability.h"

namespace rastray::stability {

void appendDepthCases(std::vector<Case>& cases) { (void)cases; }

}  // namespace rastray::stability
