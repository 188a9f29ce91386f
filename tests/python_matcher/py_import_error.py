# SPDX-License-Identifier: MIT
# py_import_error: a test fixture whose module raises while it is imported: the plugin
# is refused at load and the Python error is said on stderr.
raise ImportError("fixture: a module this plugin needs is missing")
