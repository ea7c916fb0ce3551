// geode viewer: a hex (or quad) mesh with its sheets, from the JSON in #geode-data (written by
// viewer/html.cpp). Ids shown are 1-based, as in the appendix and CSV outputs.
//
// URL hash parameters (file.html#a=1&b=2) set the initial state, so that figures and tests need
// no clicking. Sheets and face groups are named by slug (lower case, '-' -> 'm', '+' -> 'p',
// other runs -> '-'; "dome (-x,+z)" is dome-mx-pz) or by 1-based number:
//   sheets=all|none|s1,s2   surfaces shown        hide=s1,s2   surfaces hidden
//   layer=s                 the hex layer dual to sheet s     layermode=highlight|alone
//   colour=quality|layer|block|plain   shrink=0.1..1   explode=0..2   peel=N (hide N outer layers)
//   hexes=0   edges=0   groups=all|g1,g2   view=AZ,EL (degrees)   zoom=Z   ui=0   legend=0
//   probe=X,Y   hover at that pixel once loaded; the tip's text goes into #status (for tests)
(function () {
  'use strict';
  const D = JSON.parse(document.getElementById('geode-data').textContent);
  const dim = D.dim, nc = D.corners, cellName = dim === 3 ? 'hex' : 'quad', cellsName = dim === 3 ? 'hexes' : 'quads';
  const ncell = D.cells.length / nc, nnode = D.nodes.length / 3;

  const slug = (name) => name.toLowerCase().replace(/-/g, 'm').replace(/\+/g, 'p').replace(/[^a-z0-9]+/g, '-')
    .replace(/^-|-$/g, '');
  const hash = {};
  for (const kv of location.hash.slice(1).split('&')) {
    if (!kv) continue;
    const i = kv.indexOf('=');
    hash[decodeURIComponent(i < 0 ? kv : kv.slice(0, i))] = decodeURIComponent(i < 0 ? '1' : kv.slice(i + 1));
  }
  // Items named in a list parameter: 'all', 'none', or slugs / 1-based numbers.
  function picks(list, value) {
    if (value === 'all') return list.map(() => true);
    const want = value === 'none' ? [] : value.split(',');
    return list.map((x, i) => want.includes(slug(x.name)) || want.includes(String(i + 1)));
  }
  const num = (key, fallback) => (key in hash ? Number(hash[key]) : fallback);

  // ---- state ---------------------------------------------------------------------------------
  const sheetShown = 'sheets' in hash ? picks(D.sheets, hash.sheets) : D.sheets.map(() => true);
  if ('hide' in hash) picks(D.sheets, hash.hide).forEach((h, i) => { if (h) sheetShown[i] = false; });
  const groupShown = 'groups' in hash ? picks(D.groups, hash.groups) : D.groups.map(() => false);
  const layerPick = 'layer' in hash ? picks(D.sheets, hash.layer).indexOf(true) : -1;
  const S = {
    hexes: hash.hexes !== '0', edges: hash.edges !== '0', shrink: num('shrink', 1), explode: num('explode', 0),
    peel: num('peel', 0), layer: layerPick, layerMode: hash.layermode === 'alone' ? 'alone' : 'highlight',
    colour: hash.colour || (layerPick >= 0 ? 'layer' : 'quality'),
  };

  // ---- colours -------------------------------------------------------------------------------
  const palette = { tunnel: ['#2b6cb0', '#2f9e8f', '#5a4fcf'], dome: ['#e07b24', '#d64545', '#c9a227', '#b5479b', '#8c6d3f'],
    other: ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2', '#7f7f7f', '#bcbd22', '#17becf'] };
  const used = {};
  const sheetColour = D.sheets.map((s) => {
    const p = palette[s.kind] || palette.other, k = used[p === palette.other ? 'other' : s.kind] =
      (used[p === palette.other ? 'other' : s.kind] || 0) + 1;
    return new THREE.Color(p[(k - 1) % p.length]);
  });
  // Scaled Jacobian: red (0) to yellow (0.5) to blue (1); non-positive is magenta.
  const stops = [[0, [0.84, 0.19, 0.15]], [0.25, [0.99, 0.55, 0.24]], [0.5, [1.0, 0.88, 0.45]],
    [0.75, [0.6, 0.8, 0.9]], [1, [0.27, 0.46, 0.71]]];
  function qualityColour(v) {
    if (!(v > 0)) return new THREE.Color(0.8, 0.0, 0.8);
    v = Math.min(v, 1);
    let i = 1;
    while (stops[i][0] < v) ++i;
    const [a, ca] = stops[i - 1], [b, cb] = stops[i], t = (v - a) / (b - a);
    return new THREE.Color(ca[0] + t * (cb[0] - ca[0]), ca[1] + t * (cb[1] - ca[1]), ca[2] + t * (cb[2] - ca[2]));
  }
  const grey = new THREE.Color(0.86, 0.86, 0.86);
  // A layer's hexes in a lighter shade of its sheet, so that the sheet stands out between them.
  const layerColour = sheetColour.map((c) => c.clone().lerp(new THREE.Color(1, 1, 1), 0.45));
  const blockPalette = palette.other.map((c) => new THREE.Color(c));

  // ---- mesh topology: cells, centres, layers, peeling depth --------------------------------------
  const P = (n) => new THREE.Vector3(D.nodes[3 * n], D.nodes[3 * n + 1], D.nodes[3 * n + 2]);
  const node = (c, k) => D.cells[c * nc + k];
  const box = new THREE.Box3();
  for (let n = 0; n < nnode; ++n) box.expandByPoint(P(n));
  const centre = box.getCenter(new THREE.Vector3()), radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-9);
  const cellCentre = [];
  for (let c = 0; c < ncell; ++c) {
    const m = new THREE.Vector3();
    for (let k = 0; k < nc; ++k) m.add(P(node(c, k)));
    cellCentre.push(m.multiplyScalar(1 / nc));
  }
  const cellSheets = Array.from({ length: ncell }, () => []);
  D.sheets.forEach((s, i) => s.layer.forEach((c) => cellSheets[c].push(i)));
  // Cells across each facet (hex faces, quad edges), keyed by their sorted nodes.
  const facetKey = (c, f) => f.map((k) => node(c, k)).sort((a, b) => a - b).join(',');
  const facetCells = new Map();
  for (let c = 0; c < ncell; ++c)
    for (const f of D.facets) {
      const key = facetKey(c, f);
      if (!facetCells.has(key)) facetCells.set(key, []);
      facetCells.get(key).push(c);
    }
  // Peeling depth: 0 for cells on the boundary, then breadth-first inwards across facets.
  const depth = new Array(ncell).fill(-1);
  let front = [];
  for (const cs of facetCells.values()) if (cs.length === 1 && depth[cs[0]] < 0) { depth[cs[0]] = 0; front.push(cs[0]); }
  let maxDepth = 0;
  while (front.length) {
    const next = [];
    for (const c of front)
      for (const f of D.facets)
        for (const o of facetCells.get(facetKey(c, f)))
          if (depth[o] < 0) { depth[o] = depth[c] + 1; maxDepth = depth[o]; next.push(o); }
    front = next;
  }

  // ---- three.js scene --------------------------------------------------------------------------
  const view = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  view.appendChild(renderer.domElement);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0xffffff);
  const camera = new THREE.PerspectiveCamera(30, 1, radius / 100, radius * 100);
  scene.add(new THREE.AmbientLight(0xffffff, 0.55));
  const headlight = new THREE.DirectionalLight(0xffffff, 0.55);
  camera.add(headlight);
  headlight.position.set(0.3, 0.6, 1);
  scene.add(camera);
  const [az0, el0] = (hash.view || (dim === 3 ? '35,25' : '0,0')).split(',').map(Number);
  const orbit = { az: az0 * Math.PI / 180, el: el0 * Math.PI / 180, zoom: num('zoom', 1) };
  function placeCamera() {
    const d = radius / Math.sin(camera.fov * Math.PI / 360) * 1.05 / orbit.zoom;
    camera.position.set(centre.x + d * Math.cos(orbit.el) * Math.sin(orbit.az), centre.y + d * Math.sin(orbit.el),
      centre.z + d * Math.cos(orbit.el) * Math.cos(orbit.az));
    camera.lookAt(centre);
  }

  const cellGroup = new THREE.Group(), sheetGroup = new THREE.Group(), faceGroup = new THREE.Group();
  scene.add(cellGroup, sheetGroup, faceGroup);
  let pickMesh = null, pickCell = [];

  const inLayer = (c) => S.layer >= 0 && cellSheets[c].includes(S.layer);
  function cellColour(c) {
    if (S.colour === 'quality') return qualityColour(D.quality[c]);
    if (S.colour === 'layer') return inLayer(c) ? layerColour[S.layer] : grey;
    if (S.colour === 'block' && D.block) return blockPalette[D.block[c] % blockPalette.length];
    return grey;
  }
  // Where a corner of cell c is drawn: shrunk towards the cell centre, moved out by explode.
  function shown(c, k) {
    const m = cellCentre[c];
    return P(node(c, k)).sub(m).multiplyScalar(S.shrink).add(m).add(m.clone().sub(centre).multiplyScalar(S.explode));
  }

  function buildCells() {
    for (const o of cellGroup.children.slice()) { cellGroup.remove(o); o.geometry.dispose(); o.material.dispose(); }
    if (!S.hexes) { pickMesh = null; return; }
    // Category per cell: 0 hidden, 1 drawn, 2 ghost (outside the highlighted layer).
    const cat = new Array(ncell);
    for (let c = 0; c < ncell; ++c) {
      cat[c] = depth[c] < S.peel ? 0 : (S.layer < 0 || inLayer(c) ? 1 : (S.layerMode === 'alone' ? 0 : 2));
    }
    const solid = S.shrink >= 1 && S.explode === 0;
    for (const which of [1, 2]) {
      const pos = [], col = [], lines = [], owner = [];
      for (let c = 0; c < ncell; ++c) {
        if (cat[c] !== which) continue;
        const colour = which === 1 ? cellColour(c) : grey;
        const corners = [];
        for (let k = 0; k < nc; ++k) corners.push(shown(c, k));
        for (const f of D.faces) {
          // A face between two drawn cells of the same kind is hidden when nothing is shrunk.
          if (dim === 3 && solid && facetCells.get(facetKey(c, f)).every((o) => cat[o] === which)
              && facetCells.get(facetKey(c, f)).length === 2) continue;
          for (const t of [[0, 1, 2], [0, 2, 3]]) {
            for (const j of t) { const p = corners[f[j]]; pos.push(p.x, p.y, p.z); col.push(colour.r, colour.g, colour.b); }
            owner.push(c);
          }
        }
        for (const e of D.edges) for (const k of e) { const p = corners[k]; lines.push(p.x, p.y, p.z); }
      }
      if (!pos.length) continue;
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
      g.setAttribute('color', new THREE.Float32BufferAttribute(col, 3));
      const ghost = which === 2;
      const m = new THREE.Mesh(g, new THREE.MeshLambertMaterial({ vertexColors: THREE.VertexColors, side: THREE.DoubleSide,
        transparent: ghost, opacity: ghost ? 0.12 : 1, depthWrite: !ghost, polygonOffset: true, polygonOffsetFactor: 1,
        polygonOffsetUnits: 1 }));
      g.computeVertexNormals();
      cellGroup.add(m);
      if (!ghost) { pickMesh = m; pickCell = owner; }
      if (S.edges) {
        const lg = new THREE.BufferGeometry();
        lg.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
        cellGroup.add(new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: ghost ? 0xbbbbbb : 0x222222,
          transparent: ghost, opacity: ghost ? 0.5 : 1 })));
      }
    }
  }

  const sheetObjects = D.sheets.map((s, i) => {
    const g = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(s.points, 3));
    let o;
    if (s.triangles) {
      g.setIndex(s.triangles);
      if (s.smooth) g.computeVertexNormals();
      o = new THREE.Mesh(g, new THREE.MeshPhongMaterial({ color: sheetColour[i], side: THREE.DoubleSide,
        flatShading: !s.smooth, shininess: 20 }));
    } else {
      g.setIndex(s.segments);
      o = new THREE.LineSegments(g, new THREE.LineBasicMaterial({ color: sheetColour[i] }));
    }
    o.userData.sheet = i;
    sheetGroup.add(o);
    return o;
  });
  const groupObjects = D.groups.map((grp, i) => {
    const pos = [], lines = [];
    for (let q = 0; q < grp.quads.length; q += 4) {
      for (const j of [0, 1, 2, 0, 2, 3]) { const p = P(grp.quads[q + j]); pos.push(p.x, p.y, p.z); }
      for (const j of [0, 1, 1, 2, 2, 3, 3, 0]) { const p = P(grp.quads[q + j]); lines.push(p.x, p.y, p.z); }
    }
    const g = new THREE.BufferGeometry(), lg = new THREE.BufferGeometry();
    g.setAttribute('position', new THREE.Float32BufferAttribute(pos, 3));
    lg.setAttribute('position', new THREE.Float32BufferAttribute(lines, 3));
    g.computeVertexNormals();
    const o = new THREE.Group();
    o.add(new THREE.Mesh(g, new THREE.MeshLambertMaterial({ color: blockPalette[(i + 2) % blockPalette.length],
      side: THREE.DoubleSide, polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1 })));
    o.add(new THREE.LineSegments(lg, new THREE.LineBasicMaterial({ color: 0x222222 })));
    o.userData.group = i;
    faceGroup.add(o);
    return o;
  });
  // The bounding box, faint, so that sheets have a frame when the hexes are hidden.
  if (dim === 3) scene.add(new THREE.Box3Helper(box, 0xaaaaaa));

  // ---- panel and legend ----------------------------------------------------------------------
  const panel = document.getElementById('panel'), legend = document.getElementById('legend');
  const esc = (t) => String(t).replace(/[&<>"]/g, (ch) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' })[ch]);
  const hex = (c) => '#' + c.getHexString();
  function slider(key, label, min, max, step) {
    return `<div class="row"><label>${label} <input type="range" data-key="${key}" min="${min}" max="${max}" step="${step}" ` +
      `value="${S[key]}"></label></div>`;
  }
  let html = `<h1>${esc(D.title)}</h1><div class="caption">${esc(D.caption)}</div>` +
    `<div class="row"><label><input type="checkbox" data-key="hexes" ${S.hexes ? 'checked' : ''}> ${cellsName}</label> ` +
    `<label><input type="checkbox" data-key="edges" ${S.edges ? 'checked' : ''}> edges</label> ` +
    `<label>colour <select data-key="colour">${['quality', 'layer', 'block', 'plain'].filter((c) => c !== 'block' || D.block)
      .map((c) => `<option ${c === S.colour ? 'selected' : ''}>${c}</option>`).join('')}</select></label></div>` +
    slider('shrink', 'shrink', 0.2, 1, 0.05) + slider('explode', 'explode', 0, 1.5, 0.05) +
    slider('peel', `peel (0..${maxDepth})`, 0, maxDepth, 1) +
    `<div class="row"><b>${dim === 3 ? 'Sheets' : 'Chords'}</b> (surface, layer) <select data-key="layerMode">` +
    ['highlight', 'alone'].map((m) => `<option ${m === S.layerMode ? 'selected' : ''}>${m}</option>`).join('') +
    `</select></div><table><tr><td></td><td><input type="radio" name="layer" value="-1" ${S.layer < 0 ? 'checked' : ''}></td>` +
    '<td>no layer</td></tr>';
  D.sheets.forEach((s, i) => {
    html += `<tr title="${esc(slug(s.name))}: ${s.layer.length} ${cellsName}"><td><input type="checkbox" data-sheet="${i}" ` +
      `${sheetShown[i] ? 'checked' : ''}></td><td><input type="radio" name="layer" value="${i}" ${S.layer === i ? 'checked' : ''}>` +
      `</td><td><span class="swatch" style="background:${hex(sheetColour[i])}"></span> ${esc(s.name)} ` +
      `<small>(${esc(s.kind)}, ${s.layer.length})</small></td></tr>`;
  });
  html += '</table>';
  D.groups.forEach((g, i) => {
    html += `<div class="row"><label><input type="checkbox" data-group="${i}" ${groupShown[i] ? 'checked' : ''}> ` +
      `${esc(g.name)} (${g.quads.length / 4} faces)</label></div>`;
  });
  html += '<div class="caption">Drag to turn, wheel to zoom; hover for ids (1-based).</div>';
  panel.innerHTML = html;
  if (hash.ui === '0') panel.style.display = 'none';
  panel.addEventListener('input', (e) => {
    const t = e.target;
    if (t.dataset.sheet !== undefined) sheetShown[Number(t.dataset.sheet)] = t.checked;
    else if (t.dataset.group !== undefined) groupShown[Number(t.dataset.group)] = t.checked;
    else if (t.name === 'layer') { S.layer = Number(t.value); if (S.layer >= 0 && S.colour === 'quality') S.colour = 'layer'; }
    else if (t.dataset.key) S[t.dataset.key] = t.type === 'checkbox' ? t.checked : (t.type === 'range' ? Number(t.value) : t.value);
    update();
  });

  function drawLegend() {
    if (hash.legend === '0' || !S.hexes) { legend.style.display = 'none'; return; }
    if (S.colour === 'quality') {
      let lo = Infinity, hi = -Infinity;
      for (const v of D.quality) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
      const grad = stops.map(([v, c]) => `rgb(${c.map((x) => Math.round(255 * x)).join(',')}) ${100 * v}%`).join(',');
      legend.innerHTML = `<div>${esc(D.quality_name)}</div><div style="width:200px;height:12px;background:` +
        `linear-gradient(to right,${grad})"></div><div style="display:flex;justify-content:space-between;width:200px">` +
        '<span>0</span><span>0.5</span><span>1</span></div><div><span class="swatch" style="background:#cc00cc"></span> ' +
        `&le; 0 (inverted)</div><div>min ${lo.toFixed(3)}, max ${hi.toFixed(3)}</div>`;
    } else if (S.colour === 'layer' && S.layer >= 0) {
      legend.innerHTML = `<span class="swatch" style="background:${hex(layerColour[S.layer])}"></span> ` +
        `${cellsName} of the layer dual to ${esc(D.sheets[S.layer].name)} (${D.sheets[S.layer].layer.length})`;
    } else legend.innerHTML = '';
    legend.style.display = legend.innerHTML ? 'block' : 'none';
  }

  // ---- hover -----------------------------------------------------------------------------------
  const tip = document.getElementById('tip'), ray = new THREE.Raycaster(), mouse = new THREE.Vector2();
  const fmt = (p) => `(${[p.x, p.y, p.z].slice(0, dim).map((x) => +x.toPrecision(4)).join(', ')})`;
  function hover(e) {
    const r = renderer.domElement.getBoundingClientRect();
    mouse.set((e.clientX - r.left) / r.width * 2 - 1, -(e.clientY - r.top) / r.height * 2 + 1);
    ray.setFromCamera(mouse, camera);
    const targets = sheetObjects.filter((o) => o.visible && o.isMesh).concat(pickMesh ? [pickMesh] : []);
    const hit = ray.intersectObjects(targets)[0];
    let text = '';
    if (hit && hit.object === pickMesh) {
      const c = pickCell[Math.floor(hit.faceIndex)];
      let best = 0, bestD = Infinity;
      for (let k = 0; k < nc; ++k) { const d = shown(c, k).distanceTo(hit.point); if (d < bestD) { bestD = d; best = k; } }
      const n = node(c, best);
      text = `${cellName} ${c + 1}  scaled Jacobian ${D.quality[c].toFixed(3)}\n` +
        `nodes ${Array.from({ length: nc }, (_, k) => node(c, k) + 1).join(' ')}\nnode ${n + 1} ${fmt(P(n))}` +
        (cellSheets[c].length ? `\nsheets: ${cellSheets[c].map((s) => D.sheets[s].name).join(', ')}` : '');
    } else if (hit) {
      text = `${D.sheets[hit.object.userData.sheet].name} (${D.sheets[hit.object.userData.sheet].kind})`;
    }
    tip.style.display = text ? 'block' : 'none';
    tip.textContent = text;
    tip.style.left = (e.clientX + 14) + 'px';
    tip.style.top = (e.clientY + 14) + 'px';
  }

  // ---- interaction and drawing -----------------------------------------------------------------
  let drag = null;
  renderer.domElement.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY }; });
  window.addEventListener('pointerup', () => { drag = null; });
  renderer.domElement.addEventListener('pointermove', (e) => {
    if (drag) {
      orbit.az -= (e.clientX - drag.x) * 0.01;
      orbit.el = Math.max(-1.55, Math.min(1.55, orbit.el + (e.clientY - drag.y) * 0.01));
      drag = { x: e.clientX, y: e.clientY };
      draw();
    } else hover(e);
  });
  renderer.domElement.addEventListener('wheel', (e) => {
    e.preventDefault();
    orbit.zoom *= Math.exp(-e.deltaY * 0.001);
    draw();
  }, { passive: false });
  window.addEventListener('resize', draw);

  function draw() {
    const w = view.clientWidth, h = view.clientHeight;
    renderer.setSize(w, h);
    camera.aspect = w / Math.max(h, 1);
    camera.updateProjectionMatrix();
    placeCamera();
    renderer.render(scene, camera);
  }
  function update() {
    buildCells();
    sheetObjects.forEach((o, i) => { o.visible = sheetShown[i]; });
    groupObjects.forEach((o, i) => { o.visible = groupShown[i]; });
    drawLegend();
    draw();
  }
  update();
  const status = document.getElementById('status');
  if (!window.geodeErrors.length) {
    status.textContent = `viewer-ok ${cellsName}=${ncell} sheets=${D.sheets.length} shown=${sheetShown.filter((x) => x).length}` +
      ` layer=${S.layer >= 0 ? slug(D.sheets[S.layer].name) : 'none'} peel=${S.peel} depth=${maxDepth}`;
    if (hash.probe) {
      const [x, y] = hash.probe.split(',').map(Number), r = renderer.domElement.getBoundingClientRect();
      hover({ clientX: r.left + x, clientY: r.top + y });
      status.textContent += ' probe: ' + tip.textContent.replace(/\n/g, ' | ');
    }
  }
})();
