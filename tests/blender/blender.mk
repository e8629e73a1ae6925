# Blender add-on packaging (included by the main Makefile; B = build dir).
# `make package` → $(B)/ccnurbs.zip: the add-on package `ccnurbs/` with the library inside.
# Installable on Blender 3.x (Preferences > Add-ons > Install, bl_info) and laid out as a 4.2+
# extension (blender_manifest.toml at the package root, files inside one folder).
BLENDER_SAVED_GOAL := $(.DEFAULT_GOAL)
APT_PKGS  += blender zip
ADDON_SRC  = $(sort $(wildcard addon/*.py)) blender_manifest.toml

.PHONY: package deps-bpy storm
package: $(B)/ccnurbs.zip

# `make deps` also makes the Blender 4.5 / 5.x environments (PyPI `bpy` wheels, cached outside
# build/; see tests/blender/deps_bpy.sh). Skipped in a second run; a failure is reported by
# run_blender.sh as a failed suite line, not here.
deps: deps-bpy
deps-bpy:
	@./tests/deps.sh python3 python3-venv
	@./tests/blender/deps_bpy.sh

# The shipped library finds its LAPACK/BLAS/gfortran dependencies next to itself (DT_RPATH
# $$ORIGIN also serves their own dependencies), so the add-on needs nothing installed.
PKG_DEPS_RE = lapack|blas|tmglib|gfortran|quadmath
$(B)/package-lib/libccnurbs.so: $(PIC_OBJ)
	@mkdir -p $(@D)
	$(CC) -shared -o $@ $(PIC_OBJ) -Wl,--disable-new-dtags,-rpath,'$$ORIGIN' $(LDLIBS)

$(B)/ccnurbs.zip: $(ADDON_SRC) $(B)/package-lib/libccnurbs.so tests/blender/blender.mk
	@rm -rf $(B)/package && mkdir -p $(B)/package/ccnurbs
	cp $(ADDON_SRC) $(B)/package/ccnurbs/
	cp $(B)/package-lib/libccnurbs.so $(B)/package/ccnurbs/libccnurbs.so
	@for l in $$(ldd $(B)/package-lib/libccnurbs.so | awk '/=> \// {print $$3}' | grep -E '$(PKG_DEPS_RE)'); do \
	  cp -L "$$l" $(B)/package/ccnurbs/; done
	@rm -f $@.tmp && cd $(B)/package && zip -qrX ../ccnurbs.zip.tmp ccnurbs
	@mv $@.tmp $@
	@echo "package: $@"

TEST_DEPS += $(B)/ccnurbs.zip

# the long storm of artist operations (tests/blender/long_storm.sh; `make test` runs a short one)
storm: deps
	@$(MAKE) --no-print-directory build $(B)/ccnurbs.zip
	@sh tests/blender/long_storm.sh
.DEFAULT_GOAL := $(BLENDER_SAVED_GOAL)
