# The asan preset: AddressSanitizer + UndefinedBehaviorSanitizer on every target.
if(SPH_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
