#include "app/stability.h"

namespace rastray::stability {

void appendFarCases(std::vector<Case>& cases) { (void)cases; }

}  // namespace rastray::stability
