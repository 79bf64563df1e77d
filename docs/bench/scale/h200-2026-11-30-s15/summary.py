"""Prints one line per JSON of a folder: H, certificates, the call and its stages (host and GPU ms)."""
import json, pathlib, sys
for f in sorted(pathlib.Path(sys.argv[1]).glob('*.json')):
    d = json.loads(f.read_text()); t = d['timings_ms']; g = d['gpu_ms']; c = d['certificate']
    v = d.get('verify')
    print(f"{f.stem}: H {d['hausdorff']:.16g} cert {c['a_to_b']['confirmed']}/{c['b_to_a']['confirmed']}"
          + (f" verify ok={v['ok']} max|diff| {v['max_abs_diff']}" if v else '')
          + f" | call {t['total']:.0f} pieces {t.get('pieces', 0):.0f} | host upload {t['upload']:.0f} index {t['index']:.0f}"
          f" cull {t['cull']:.0f} check {t['check']:.0f} | gpu upload {g['upload']:.0f} index {g['index']:.0f}"
          f" cull {g['cull']:.0f} search {g['search']:.0f} refine {g['refine']:.0f} | bits {d['counters']['a_to_b']['bits']}")
