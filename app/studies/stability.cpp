#include "app/studies/stability.h"

namespace rastray::stability {

std::vector<Case> allCases() {
  std::vector<Case> cases;
  appendDepthCases(cases);
  appendFarCases(cases);
  appendGeometryCases(cases);
  appendOpticsCases(cases);
  appendLayerCases(cases);
  appendLightCases(cases);
  return cases;
}

}  // namespace rastray::stability
