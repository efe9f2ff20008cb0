# Finds Debian's ROS 1 bag library (librosbag-storage-dev, pulled in by librosbag-dev) and the
# message headers of libgeometry-msgs-dev and libtf2-msgs-dev, as the imported target
# RosbagStorage::RosbagStorage. Neither of the packages' own files serves: rosbag_storage.pc
# requires a pluginlib.pc that Debian does not ship, and the catkin-generated
# rosbag_storageConfig.cmake runs ament's Python templates at configure time. rosbag/bag.h
# includes pluginlib (a ROS 2 package in Debian, with its headers one folder deeper) and,
# through it, class_loader, rcpputils, rcutils and ament_index_cpp: their include folders
# are found here too. The libraries linked are those whose symbols the reader uses directly.
include(FindPackageHandleStandardArgs)

find_path(RosbagStorage_INCLUDE_DIR rosbag/bag.h)
find_path(RosbagStorage_GEOMETRY_MSGS_DIR geometry_msgs/PoseStamped.h)
find_path(RosbagStorage_TF2_MSGS_DIR tf2_msgs/TFMessage.h)
set(_rosbag_nested "")
foreach(_pair pluginlib:pluginlib/class_loader.hpp class_loader:class_loader/class_loader.hpp
              rcpputils:rcpputils/shared_library.hpp rcutils:rcutils/logging_macros.h
              ament_index_cpp:ament_index_cpp/get_resource.hpp)
  string(REPLACE ":" ";" _pair "${_pair}")
  list(GET _pair 0 _dir)
  list(GET _pair 1 _header)
  find_path(RosbagStorage_${_dir}_DIR ${_header} PATH_SUFFIXES ${_dir})
  list(APPEND _rosbag_nested RosbagStorage_${_dir}_DIR)
endforeach()
foreach(_lib rosbag_storage roscpp_serialization rostime cpp_common console_bridge)
  find_library(RosbagStorage_${_lib}_LIBRARY ${_lib})
  list(APPEND _rosbag_libs RosbagStorage_${_lib}_LIBRARY)
endforeach()

find_package_handle_standard_args(RosbagStorage
  REQUIRED_VARS RosbagStorage_INCLUDE_DIR RosbagStorage_GEOMETRY_MSGS_DIR
                RosbagStorage_TF2_MSGS_DIR ${_rosbag_nested} ${_rosbag_libs})

if(RosbagStorage_FOUND AND NOT TARGET RosbagStorage::RosbagStorage)
  add_library(RosbagStorage::RosbagStorage INTERFACE IMPORTED)
  set(_dirs ${RosbagStorage_INCLUDE_DIR} ${RosbagStorage_GEOMETRY_MSGS_DIR}
            ${RosbagStorage_TF2_MSGS_DIR})
  foreach(_var ${_rosbag_nested})
    list(APPEND _dirs ${${_var}})
  endforeach()
  list(REMOVE_DUPLICATES _dirs)
  set(_libs "")
  foreach(_var ${_rosbag_libs})
    list(APPEND _libs ${${_var}})
  endforeach()
  set_target_properties(RosbagStorage::RosbagStorage PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${_dirs}" INTERFACE_LINK_LIBRARIES "${_libs}")
endif()
