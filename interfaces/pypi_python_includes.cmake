# The ROS 2 wheels on PyPI export their Python targets with the include folder of the
# machine that built them (/opt/python/...); use this interpreter's instead. Included by
# each interface package after rosidl_generate_interfaces.
get_directory_property(_imported IMPORTED_TARGETS)
foreach(_target IN LISTS _imported)
  if(_target MATCHES "__rosidl_generator_py$")
    get_target_property(_inc ${_target} INTERFACE_INCLUDE_DIRECTORIES)
    if(_inc)
      list(FILTER _inc EXCLUDE REGEX "^/opt/python/")
      list(APPEND _inc ${Python3_INCLUDE_DIRS})
      list(REMOVE_DUPLICATES _inc)
      set_target_properties(${_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_inc}")
    endif()
  endif()
endforeach()
