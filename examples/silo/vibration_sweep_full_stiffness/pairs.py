# Paired changes against the still run of the same angle and seed (rate, axis and wall speed in the hopper, outlet density and speed): python3 pairs.py STILL_CAMPAIGN CAMPAIGN...
import json, glob, os, re, sys, statistics as st
def load(camp):
    out = {}
    for d in glob.glob(camp + '/runs/*/summary.json'):
        m = re.search(r'theta([\d.]+)_f([\d.]+)_seed(\d+)', d)
        s = json.load(open(d))
        out[(float(m[1]), float(m[2]), int(m[3]))] = s
    return out
still_src = load(sys.argv[1])
for camp in sys.argv[1:]:
    runs = load(camp)
    print('==', os.path.basename(camp))
    keys = sorted({(t, f) for (t, f, s) in runs if f > 0})
    for t, f in keys:
        ch = {'rate': [], 'axis': [], 'wall': [], 'ratio': [], 'dens': [], 'speed': []}
        for (tt, ff, seed), s in runs.items():
            if (tt, ff) != (t, f) or (t, 0.0, seed) not in still_src: continue
            b = still_src[(t, 0.0, seed)]
            ch['rate'].append(100 * (s['rate']['rate_kg_s'] / b['rate']['rate_kg_s'] - 1))
            ch['axis'].append(100 * (s['flow_pattern']['axis_speed_m_s'] / b['flow_pattern']['axis_speed_m_s'] - 1))
            ch['wall'].append(100 * (s['flow_pattern']['wall_speed_m_s'] / b['flow_pattern']['wall_speed_m_s'] - 1))
            if s.get('outlet_flow') and b.get('outlet_flow'):
                ch['dens'].append(100 * (s['outlet_flow']['solid_density_kg_m3'] / b['outlet_flow']['solid_density_kg_m3'] - 1))
                ch['speed'].append(100 * (s['outlet_flow']['downward_speed_m_s'] / b['outlet_flow']['downward_speed_m_s'] - 1))
            ch['ratio'].append(s['flow_pattern']['wall_to_axis_velocity_ratio'] - b['flow_pattern']['wall_to_axis_velocity_ratio'])
        def fmt(v):
            if not v: return '-'
            se = st.stdev(v) / len(v) ** 0.5 if len(v) > 1 else float('nan')
            return f"{st.mean(v):+.1f} ({se:.1f}) [" + ', '.join(f'{x:+.1f}' for x in v) + "]"
        print(f"theta {t:g} f {f:g}: n={len(ch['rate'])} rate {fmt(ch['rate'])} | axis {fmt(ch['axis'])} | wall {fmt(ch['wall'])} | outlet dens {fmt(ch['dens'])} speed {fmt(ch['speed'])} | ratio {st.mean(ch['ratio']) if ch['ratio'] else float('nan'):+.3f}")
