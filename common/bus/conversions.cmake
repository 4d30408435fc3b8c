# Conversions between the algorithm libraries' types and their messages, one small library per
# algorithm library so that nudge_bus depends on none of them. Included from common/ once every
# library folder is configured (a library left out with NUDGE_EXCLUDE has no conversions).
if(TARGET nudge_tracking)
  add_library(nudge_bus_tracking ${CMAKE_CURRENT_LIST_DIR}/src/track_convert.cpp)
  target_link_libraries(nudge_bus_tracking PUBLIC nudge_bus_symmetry nudge_tracking)
endif()
if(TARGET nudge_geometry)
  add_library(nudge_bus_geometry ${CMAKE_CURRENT_LIST_DIR}/src/axes_convert.cpp)
  target_link_libraries(nudge_bus_geometry PUBLIC nudge_bus nudge_geometry)
endif()
if(TARGET nudge_robot)
  add_library(nudge_bus_robot ${CMAKE_CURRENT_LIST_DIR}/src/arm_convert.cpp)
  target_link_libraries(nudge_bus_robot PUBLIC nudge_bus nudge_robot)
endif()
if(TARGET nudge_viewer)
  add_library(nudge_bus_viewer ${CMAKE_CURRENT_LIST_DIR}/src/viewer_convert.cpp)
  target_link_libraries(nudge_bus_viewer PUBLIC nudge_bus nudge_viewer)
endif()
