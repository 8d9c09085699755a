"""lcmgen: the steps of lcm_codec_gen.py -- parse (the .lcm files), fingerprint
and sizes (LCM's wire rules), schema (JSON Schema) and emit (the C++, from the
Jinja2 templates in ../templates)."""
