# ROS 2 wheels from PyPI export include paths of the machine they were built on
# (/opt/python/...). drop_wheel_include_paths() removes those from every imported Python
# generator target found so far, so a build against the wheels configures; a no-op on a
# normal ROS 2 installation. Used by this package and by the project's wrapper that builds
# FlexBE's interface packages (test/flexbe_env/interfaces).
function(drop_wheel_include_paths)
  get_property(_imported DIRECTORY PROPERTY IMPORTED_TARGETS)
  foreach(_target IN LISTS _imported)
    if(_target MATCHES "__rosidl_generator_py$")
      get_target_property(_includes ${_target} INTERFACE_INCLUDE_DIRECTORIES)
      if(_includes)
        list(FILTER _includes EXCLUDE REGEX "^/opt/python/")
        set_target_properties(${_target} PROPERTIES INTERFACE_INCLUDE_DIRECTORIES "${_includes}")
      endif()
    endif()
  endforeach()
endfunction()
