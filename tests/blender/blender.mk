# Blender add-on tests (included by the main Makefile; B = build dir).
# `make package` (rules in tests/package/package.mk) → one extension zip per platform, and
# $(B)/ccnurbs.zip = the linux-x64 one: the add-on package `ccnurbs/` with the library inside,
# installable on Blender 3.x (Preferences > Add-ons > Install, bl_info) and laid out as a 4.2+
# extension (blender_manifest.toml at the package root, files inside one folder).
BLENDER_SAVED_GOAL := $(.DEFAULT_GOAL)
APT_PKGS  += blender zip

.PHONY: package deps-bpy storm
package: $(B)/ccnurbs.zip

# `make deps` also makes the Blender 4.2 / 4.5 / 5.2 / 5.3 environments (PyPI `bpy` wheels, cached
# outside build/; see tests/blender/deps_bpy.sh). Skipped in a second run; a failure is reported by
# run_blender.sh as a failed suite line, not here.
deps: deps-bpy
deps-bpy:
	@./tests/deps.sh python3 python3-venv
	@./tests/blender/deps_bpy.sh

TEST_DEPS += $(B)/ccnurbs.zip

# the long storm of artist operations (tests/blender/long_storm.sh; `make test` runs a short one)
storm: deps
	@$(MAKE) --no-print-directory build $(B)/ccnurbs.zip
	@sh tests/blender/long_storm.sh
.DEFAULT_GOAL := $(BLENDER_SAVED_GOAL)
