# The build every ROS 2 interface package of ours shares (those in this folder and
# ros_bridge/interfaces/labware_interfaces): for rclpy only. Each package's CMakeLists.txt names its
# project and its message dependencies (INTERFACE_DEPENDENCIES), then includes this file.
#
# rclpy needs only the C side: rosidl_generator_py brings in the type description and C generators
# and the C type supports. Finding the message packages also registers the C++ generators, which
# roughly double the build; keep only those Python needs.
find_package(ament_cmake REQUIRED)
find_package(rosidl_cmake REQUIRED)
find_package(rosidl_generator_py REQUIRED)
foreach(_dependency ${INTERFACE_DEPENDENCIES})
  find_package(${_dependency} REQUIRED)
endforeach()

file(GLOB _actions RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} action/*.action)
file(GLOB _messages RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} msg/*.msg)
file(GLOB _services RELATIVE ${CMAKE_CURRENT_SOURCE_DIR} srv/*.srv)

list(FILTER AMENT_EXTENSIONS_rosidl_generate_idl_interfaces INCLUDE REGEX
  "^rosidl_(generator_type_description|generator_c|typesupport_c|typesupport_introspection_c|typesupport_fastrtps_c|generator_py):")

rosidl_generate_interfaces(${PROJECT_NAME}
  ${_messages} ${_services} ${_actions}
  DEPENDENCIES ${INTERFACE_DEPENDENCIES}
)

ament_export_dependencies(rosidl_default_runtime)
ament_package()
