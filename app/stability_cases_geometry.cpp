#include "app/stability.h"

namespace rastray::stability {

void appendGeometryCases(std::vector<Case>& cases) { (void)cases; }

}  // namespace rastray::stability
