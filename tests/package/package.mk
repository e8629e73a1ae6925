# Per-platform packages (included by the main Makefile; B = build dir). `make package` builds, on
# this Linux machine, one Blender extension zip per platform, named as Blender's
# `extension build --split-platforms` names them, each manifest declaring its one platform:
#   $(B)/ccnurbs-<version>-linux_x64.zip     libccnurbs.so     glibc symbol versions <= 2.28
#   $(B)/ccnurbs-<version>-windows_x64.zip   ccnurbs.dll
#   $(B)/ccnurbs-<version>-macos_arm64.zip   libccnurbs.dylib  (macOS 11+)
#   $(B)/ccnurbs-<version>-macos_x64.zip     libccnurbs.dylib  (macOS 11+)
# and $(B)/<platform>/: the library, the CLI (ccnurbs / ccnurbs.exe) and OpenBLAS beside them.
# $(B)/ccnurbs.zip (tests/blender/run_blender.sh, make demo) is the linux-x64 package.
# Toolchains from PyPI only (tests/package/deps_xbuild.sh, cached in $(CCN_CACHE)/xbuild): Zig's C
# compiler (`ziglang`) and, per platform, OpenBLAS with LAPACKE from `scipy-openblas32` (one
# self-contained shared library, shipped next to ours; its symbols are prefixed scipy_, mapped by
# a generated header, see tests/package/compat.h). No Debian library goes into any package.
# Tests: tests/package/run_wine.sh (Windows C suite + CLI under Wine), run_package.sh (the zips
# validated, glibc versions, macOS link check, what runs where).
PKG_SAVED_GOAL := $(.DEFAULT_GOAL)
PKG_MK        := $(lastword $(MAKEFILE_LIST))
PKG_ZIG       = 0.15.2
PKG_OPENBLAS  = 0.3.34.481.3
PKG_PLATFORMS = linux-x64 windows-x64 macos-arm64 macos-x64
PKG_VERSION  := $(shell sed -n 's/^version *= *"\(.*\)"/\1/p' blender_manifest.toml)
CCN_CACHE    ?= $(or $(XDG_CACHE_HOME),$(HOME)/.cache)/ccnurbs
XC            = $(CCN_CACHE)/xbuild
XREADY        = $(XC)/ready-$(PKG_ZIG)-$(PKG_OPENBLAS)
ZIG           = ZIG_GLOBAL_CACHE_DIR=$(XC)/zig-cache ZIG_LOCAL_CACHE_DIR=$(XC)/zig-cache \
                $(XC)/venv-zig-$(PKG_ZIG)/bin/python -m ziglang
# Release builds (no debug information in the packages)
PKG_CFLAGS   ?= -O2
ADDON_SRC     = $(sort $(wildcard addon/*.py)) blender_manifest.toml
# wine64: tests/package/run_wine.sh; llvm: llvm-objdump/llvm-nm for the Mach-O link check
APT_PKGS     += wine64 llvm binutils zip
DEPS_SCRIPTS += tests/package/deps_wine.sh

# per platform: Zig target, library, OpenBLAS library, executable suffix, link flags
PKG_TARGET_linux-x64   = x86_64-linux-gnu.2.28
PKG_TARGET_windows-x64 = x86_64-windows-gnu
PKG_TARGET_macos-arm64 = aarch64-macos.11.0
PKG_TARGET_macos-x64   = x86_64-macos.11.0
PKG_LIB_linux-x64      = libccnurbs.so
PKG_LIB_windows-x64    = ccnurbs.dll
PKG_LIB_macos-arm64    = libccnurbs.dylib
PKG_LIB_macos-x64      = libccnurbs.dylib
PKG_OB_linux-x64       = libscipy_openblas.so
PKG_OB_windows-x64     = libscipy_openblas.dll
PKG_OB_macos-arm64     = libscipy_openblas.dylib
PKG_OB_macos-x64       = libscipy_openblas.dylib
PKG_EXE_windows-x64    = .exe
# the library and the CLI find OpenBLAS in their own folder
PKG_RPATH_linux-x64    = -Wl,--disable-new-dtags,-rpath,'$$ORIGIN'
PKG_RPATH_macos-arm64  = -Wl,-rpath,@loader_path
PKG_RPATH_macos-x64    = -Wl,-rpath,@loader_path
PKG_SONAME_linux-x64   = -Wl,-soname,libccnurbs.so
PKG_SONAME_macos-arm64 = -Wl,-install_name,@rpath/libccnurbs.dylib
PKG_SONAME_macos-x64   = -Wl,-install_name,@rpath/libccnurbs.dylib
PKG_LIBS_linux-x64     = -lm -lpthread
# macOS: <malloc.h> for csrc/tools (tests/package/mac/malloc.h); _SC_NPROCESSORS_ONLN, which
# Darwin hides under a plain _POSIX_C_SOURCE
PKG_INC_macos-arm64    = -Itests/package/mac -D_DARWIN_C_SOURCE
PKG_INC_macos-x64      = -Itests/package/mac -D_DARWIN_C_SOURCE
# Windows links OpenBLAS through its import library; the others through the shared library itself
PKG_OBLINK_windows-x64 = scipy_openblas32/lib/libscipy_openblas.lib

# Windows test builds only: <sys/resource.h> for tests/c/test_badinput*.c
PKG_TESTFLAGS_windows-x64 = -Itests/package/win

PKG_CLI_SRC = $(wildcard csrc/tools/*.c)
PKG_ZIPS    = $(foreach p,$(PKG_PLATFORMS),$(B)/ccnurbs-$(PKG_VERSION)-$(subst -,_,$(p)).zip)
WIN_TEST_BIN = $(TEST_SRC:tests/c/%.c=$(B)/windows-x64/tests/%.exe)

.PHONY: package-all deps-xbuild
package: package-all
package-all: $(PKG_ZIPS) $(B)/ccnurbs.zip \
             $(foreach p,$(PKG_PLATFORMS),$(B)/$(p)/ccnurbs$(PKG_EXE_$(p)))
	@for z in $(PKG_ZIPS); do echo "package: $$z"; done
deps: deps-xbuild
deps-xbuild: $(XREADY)
$(XREADY):
	@./tests/deps.sh python3 python3-venv
	@CCN_CACHE=$(CCN_CACHE) sh tests/package/deps_xbuild.sh $(PKG_ZIG) $(PKG_OPENBLAS)

# PKG_PLATFORM_RULES,platform: objects, library, OpenBLAS copy, CLI, staged package, zip
define PKG_PLATFORM_RULES
PKG_OBD_$(1)  = $$(XC)/openblas-$$(PKG_OPENBLAS)/$(1)
PKG_CC_$(1)   = $$(ZIG) cc -target $$(PKG_TARGET_$(1)) -include tests/package/compat.h \
                -I$$(PKG_OBD_$(1)) -I$$(PKG_OBD_$(1))/scipy_openblas32/include $$(PKG_INC_$(1)) \
                $$(CPPFLAGS) $$(WARN) $$(PKG_CFLAGS) $$(if $$(filter linux-%,$(1)),-fPIC)
PKG_OBJ_$(1)  = $$(LIB_SRC:csrc/%.c=$$(B)/xobj/$(1)/%.o)
PKG_OBL_$(1)  = $$(PKG_OBD_$(1))/$$(or $$(PKG_OBLINK_$(1)),scipy_openblas32/lib/$$(PKG_OB_$(1)))
PKG_DIR_$(1)  = $$(B)/xpkg/$(1)/ccnurbs

$$(B)/xobj/$(1)/%.o: csrc/%.c $$(HDRS) tests/package/compat.h $$(XREADY)
	@mkdir -p $$(@D)
	$$(PKG_CC_$(1)) -c $$< -o $$@ || { rm -f $$@; exit 1; }
# the library: OpenBLAS beside it ($$(B)/$(1)/ is what a package ships, plus the CLI)
$$(B)/$(1)/$$(PKG_OB_$(1)): $$(XREADY)
	@mkdir -p $$(@D)
	cp $$(PKG_OBD_$(1))/scipy_openblas32/lib/$$(PKG_OB_$(1)) $$@
$$(B)/$(1)/$$(PKG_LIB_$(1)): $$(PKG_OBJ_$(1)) $$(B)/$(1)/$$(PKG_OB_$(1))
	$$(PKG_CC_$(1)) -shared -o $$@ $$(PKG_OBJ_$(1)) \
	  $$(PKG_SONAME_$(1)) $$(PKG_RPATH_$(1)) $$(PKG_OBL_$(1)) $$(PKG_LIBS_$(1))
	@rm -f $$(B)/$(1)/*.pdb $$(B)/$(1)/*.lib
$$(B)/$(1)/libccnurbs.a: $$(PKG_OBJ_$(1))
	@rm -f $$@
	$$(ZIG) ar rcs $$@ $$^
$$(B)/$(1)/ccnurbs$$(PKG_EXE_$(1)): $$(PKG_CLI_SRC) $$(B)/$(1)/libccnurbs.a $$(B)/$(1)/$$(PKG_OB_$(1)) $$(HDRS)
	$$(PKG_CC_$(1)) $$(PKG_CLI_SRC) -o $$@ $$(B)/$(1)/libccnurbs.a $$(PKG_RPATH_$(1)) \
	  $$(PKG_OBL_$(1)) $$(PKG_LIBS_$(1))
	@rm -f $$(B)/$(1)/*.pdb $$(B)/$(1)/*.lib

# tests/package/loadcheck.c: loads the packaged library as the add-on does (own folder: on
# Windows no OpenBLAS beside the executable, so the package folder must provide it)
$$(B)/$(1)/loadcheck/loadcheck$$(PKG_EXE_$(1)): tests/package/loadcheck.c csrc/include/ccnurbs.h $$(XREADY)
	@mkdir -p $$(@D)
	$$(ZIG) cc -target $$(PKG_TARGET_$(1)) -Icsrc/include -std=c11 -Wall -Wextra -Werror $$(PKG_CFLAGS) \
	  $$< -o $$@ $$(if $$(filter linux-%,$(1)),-ldl)
	@rm -f $$(@D)/*.pdb $$(@D)/*.lib

$$(B)/ccnurbs-$$(PKG_VERSION)-$(subst -,_,$(1)).zip: $$(ADDON_SRC) $$(B)/$(1)/$$(PKG_LIB_$(1)) \
    $$(B)/$(1)/$$(PKG_OB_$(1)) $$(PKG_MK)
	@rm -rf $$(PKG_DIR_$(1)) && mkdir -p $$(PKG_DIR_$(1))
	cp $$(ADDON_SRC) $$(B)/$(1)/$$(PKG_LIB_$(1)) $$(B)/$(1)/$$(PKG_OB_$(1)) $$(PKG_DIR_$(1))/
	sed -i 's/^platforms *=.*/platforms = ["$(1)"]/' $$(PKG_DIR_$(1))/blender_manifest.toml
	@grep -qx 'platforms = \["$(1)"\]' $$(PKG_DIR_$(1))/blender_manifest.toml
	@rm -f $$@.tmp && cd $$(B)/xpkg/$(1) && zip -qrX $$(abspath $$@).tmp ccnurbs
	@mv $$@.tmp $$@
endef
$(foreach p,$(PKG_PLATFORMS),$(eval $(call PKG_PLATFORM_RULES,$(p))))

# $(B)/ccnurbs.zip (tests/blender/run_blender.sh, make demo): the linux-x64 package
$(B)/ccnurbs.zip: $(B)/ccnurbs-$(PKG_VERSION)-linux_x64.zip
	cp $< $@

# The C tests for Windows (run under Wine by tests/package/run_wine.sh), linked like the CLI,
# OpenBLAS beside them.
$(B)/windows-x64/tests/%.exe: tests/c/%.c $(B)/windows-x64/libccnurbs.a \
    $(B)/windows-x64/tests/libscipy_openblas.dll $(HDRS)
	$(PKG_CC_windows-x64) -Itests/c $(PKG_TESTFLAGS_windows-x64) $< -o $@ \
	  $(B)/windows-x64/libccnurbs.a $(PKG_OBL_windows-x64)
	@rm -f $(@D)/$*.pdb $(@D)/$*.lib
$(B)/windows-x64/tests/libscipy_openblas.dll: $(B)/windows-x64/libscipy_openblas.dll
	@mkdir -p $(@D)
	cp $< $@

TEST_DEPS += package-all $(WIN_TEST_BIN) $(foreach p,$(PKG_PLATFORMS),$(B)/$(p)/loadcheck/loadcheck$(PKG_EXE_$(p)))
.DEFAULT_GOAL := $(PKG_SAVED_GOAL)
