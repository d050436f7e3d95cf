# Install rules and the exported package: find_package(resoct 0.1 COMPONENTS io cpu vulkan)
# works from the install tree and from the build tree.
set(RESOCT_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/resoct)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/resoct DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        PATTERN "vulkan" EXCLUDE)
install(FILES ${RESOCT_GENERATED_INCLUDE_DIR}/resoct/version.hpp
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/resoct)
if(RESOCT_WITH_VULKAN)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/resoct/vulkan
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/resoct)
endif()

foreach(component core io cpu vulkan)
  if(TARGET resoct_${component})
    install(TARGETS resoct_${component} EXPORT resoct-${component}-targets
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
            RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
            INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
    install(EXPORT resoct-${component}-targets NAMESPACE resoct:: DESTINATION ${RESOCT_CMAKE_DIR})
    export(EXPORT resoct-${component}-targets NAMESPACE resoct::
           FILE ${PROJECT_BINARY_DIR}/resoct-${component}-targets.cmake)
  endif()
endforeach()

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/resoctConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/resoctConfig.cmake
                              INSTALL_DESTINATION ${RESOCT_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/resoctConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/resoctConfig.cmake ${PROJECT_BINARY_DIR}/resoctConfigVersion.cmake
        DESTINATION ${RESOCT_CMAKE_DIR})
