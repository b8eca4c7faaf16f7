# Placeholder until the OpenFOAM header preparation lands: the participant is disabled.
set(COREDEM_OPENFOAM_ENABLED OFF)
if(COREDEM_OPENFOAM STREQUAL "ON")
  message(FATAL_ERROR "COREDEM_OPENFOAM=ON is not supported yet.")
endif()
