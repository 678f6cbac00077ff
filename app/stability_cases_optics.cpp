#include "app/stability.h"

namespace rastray::stability {

void appendOpticsCases(std::vector<Case>& cases) { (void)cases; }

}  // namespace rastray::stability
