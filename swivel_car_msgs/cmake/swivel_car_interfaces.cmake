# What every interface package of this workspace (swivel_car_msgs, and tf2_msgs where the
# underlay has none) does alike; included before rosidl_generate_interfaces.

# Every language by default, as a Jazzy user building this package expects. Our own nodes are
# all Python: `make build` turns the C++ generators off, which halves the build (45 s -> 29 s
# on our 2 cores); the C typesupports that rclpy loads are built either way.
option(SWIVEL_CAR_MSGS_CPP "generate the C++ interfaces and typesupports too" ON)
if(NOT SWIVEL_CAR_MSGS_CPP)
  list(FILTER AMENT_EXTENSIONS_rosidl_generate_idl_interfaces EXCLUDE REGEX "_cpp:")
endif()

# The C and C++ files rosidl generates, one per interface and typesupport, are compiled as one
# file per library and core (CMake's unity build): each file of the Fast DDS typesupport parses
# the same Fast CDR headers again. The generators' Python (rosidl_parser, empy) then takes most
# of the build. Off by default, as colcon builds a package; `make build` turns it on. The type
# description sources each define the same static names (one per referenced type), so they
# stay files of their own.
option(SWIVEL_CAR_MSGS_UNITY_BUILD "compile each interface library's sources as one" OFF)
function(swivel_car_unity_build)
  if(NOT SWIVEL_CAR_MSGS_UNITY_BUILD)
    return()
  endif()
  get_property(targets DIRECTORY PROPERTY BUILDSYSTEM_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(type ${target} TYPE)
    if(NOT type MATCHES "^(SHARED|MODULE|STATIC)_LIBRARY$")
      continue()
    endif()
    set_target_properties(${target} PROPERTIES UNITY_BUILD ON)
    get_target_property(sources ${target} SOURCES)
    foreach(source IN LISTS sources)
      if(source MATCHES "__description\\.c$")
        set_source_files_properties(${source} TARGET_DIRECTORY ${target}
          PROPERTIES SKIP_UNITY_BUILD_INCLUSION ON)
      endif()
    endforeach()
  endforeach()
endfunction()

# The ROS 2 wheels from PyPI were built in a manylinux container, and the CMake targets that
# their message packages export (e.g. std_msgs::std_msgs__rosidl_generator_py) still name that
# container's interpreter: /opt/python/cp311-cp311/include/python3.11 and its numpy include
# directory. CMake rejects imported targets whose include directories do not exist, so the
# Python bindings of our interfaces would not build. Point every imported target we link
# against at this interpreter's include directories instead, with
# swivel_car_fix_wheel_include_dirs() after rosidl_generate_interfaces. This is the only place
# that knows.
# Development.Module, as rosidl_generator_py finds it: the embedding part (Development) took
# another 1.6 s of the configure, which every build of this package waits for.
find_package(Python3 REQUIRED COMPONENTS Interpreter Development.Module NumPy)
function(swivel_car_fix_wheel_include_dirs)
  get_property(targets DIRECTORY PROPERTY IMPORTED_TARGETS)
  foreach(target IN LISTS targets)
    get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
    if(NOT dirs)
      continue()
    endif()
    set(fixed_dirs "")
    foreach(dir IN LISTS dirs)
      if(dir MATCHES "^/opt/python/cp[0-9]+-cp[0-9]+/")
        if(dir MATCHES "numpy")
          list(APPEND fixed_dirs ${Python3_NumPy_INCLUDE_DIRS})
        else()
          list(APPEND fixed_dirs ${Python3_INCLUDE_DIRS})
        endif()
      else()
        list(APPEND fixed_dirs ${dir})
      endif()
    endforeach()
    list(REMOVE_DUPLICATES fixed_dirs)
    set_target_properties(${target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${fixed_dirs}")
  endforeach()
endfunction()
