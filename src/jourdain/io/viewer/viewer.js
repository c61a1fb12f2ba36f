/* jourdain's 3-D view of a simulated motion (src/jourdain/io/viewer/__init__.py writes the page).
 *
 * Reads the scene from the JSON script element "jourdain-scene" and draws it with
 * three.js (the global JD3 of three_bundle.js): one group per body, placed at each time by the
 * body frame's inertial position r_O and orientation S (as a quaternion), with the body's
 * equivalent box or ellipsoid (or its visuals) and a triad of the body frame inside it, a triad of
 * each joint frame fixed to the parent, and the spring-dampers as lines between their points
 * (an elastic body: its nodes joined by a line that bends with it);
 * a closed system's closing joints: red lines from each body's origin to its point, a marker.
 *
 * Poses: a Float32Array (base64) of n_frames × n_bodies × 7 numbers (x, y, z, qx, qy, qz, qw);
 * between two frames positions are interpolated linearly and orientations by slerp.
 *
 * Page address: #t=1.5 opens paused at t = 1.5 s; #t=1.5&play plays from there.
 * window.jourdainViewer: times, bodies, setTime(t), time(), play(), pause(), bodyPosition(name, t),
 * comPosition(name, t), bodyQuaternion(name, t) (read from the three.js objects' world matrices).
 */
(function () {
  "use strict";
  var T = window.JD3;
  var root = document.getElementById("jourdain-view");
  var scene = JSON.parse(document.getElementById("jourdain-scene").textContent);

  function decode(b64, Type) {
    var s = atob(b64);
    var bytes = new Uint8Array(s.length);
    for (var i = 0; i < s.length; i++) bytes[i] = s.charCodeAt(i);
    return new Type(bytes.buffer);
  }

  var times = decode(scene.times, Float64Array);
  var poses = decode(scene.poses, Float32Array);
  var nb = scene.bodies.length;
  var nf = times.length;
  var up = new T.Vector3().fromArray(scene.up);
  var L = scene.extent;

  // --- renderer, camera, controls ----------------------------------------------------------
  var canvasBox = root.querySelector(".jv-canvas");
  var renderer;
  try {
    renderer = new T.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  } catch (err) {
    canvasBox.textContent = "This browser cannot draw WebGL: the 3-D view is not available.";
    return;
  }
  renderer.setPixelRatio(window.devicePixelRatio || 1);
  canvasBox.appendChild(renderer.domElement);
  var world = new T.Scene();
  world.background = new T.Color(0xf7f7f7);
  var camera = new T.PerspectiveCamera(40, 1, L * 1e-3, L * 100);
  camera.up.copy(up);
  var center = new T.Vector3().fromArray(scene.center);
  camera.position.copy(center).addScaledVector(new T.Vector3().fromArray(scene.view_dir),
                                                 scene.distance);
  var controls = new T.OrbitControls(camera, renderer.domElement);
  controls.target.copy(center);
  controls.update();

  world.add(new T.HemisphereLight(0xffffff, 0x8090a0, 2.0));
  var sun = new T.DirectionalLight(0xffffff, 1.6);
  sun.position.copy(center).addScaledVector(up, 2 * L).addScaledVector(
    new T.Vector3().fromArray(scene.view_dir), 2 * L);
  sun.target.position.copy(center);
  world.add(sun, sun.target);

  // ground grid perpendicular to "up", below the motion
  var grid = new T.GridHelper(1.5 * L, 15, 0xc4c4c4, 0xe4e4e4);
  grid.quaternion.setFromUnitVectors(new T.Vector3(0, 1, 0), up);
  grid.position.fromArray(scene.ground);
  world.add(grid);

  function triad(size, opacity) {
    var g = new T.BufferGeometry();
    g.setAttribute("position", new T.BufferAttribute(new Float32Array(
      [0, 0, 0, size, 0, 0, 0, 0, 0, 0, size, 0, 0, 0, 0, 0, 0, size]), 3));
    g.setAttribute("color", new T.BufferAttribute(new Float32Array(
      [0.85, 0.1, 0.1, 0.85, 0.1, 0.1, 0.1, 0.6, 0.1, 0.1, 0.6, 0.1, 0.1, 0.25, 0.9,
       0.1, 0.25, 0.9]), 3));
    return new T.LineSegments(g, new T.LineBasicMaterial({
      vertexColors: true, transparent: opacity < 1, opacity: opacity }));
  }

  function place(obj, spec) {
    obj.position.fromArray(spec.position);
    obj.quaternion.fromArray(spec.quaternion);
    if (spec.scale) obj.scale.fromArray(spec.scale);
  }

  // a visual: a mesh (triangles), box, cylinder (radius, length along z) or sphere (radius)
  function visual(v, colour) {
    var geo;
    var base = { color: v.color ? new T.Color().fromArray(v.color) : colour, roughness: 0.6,
                 metalness: 0.05, side: T.DoubleSide };
    if (v.kind === "mesh") {  // indexed triangles, flat shaded (CAD meshes have hard edges)
      geo = new T.BufferGeometry();
      geo.setAttribute("position", new T.BufferAttribute(decode(v.vertices, Float32Array), 3));
      geo.setIndex(new T.BufferAttribute(decode(v.indices, Uint32Array), 1));
      geo.computeVertexNormals();
      var mats = v.groups.map(function (gr, n) {
        geo.addGroup(3 * gr[0], 3 * gr[1], n);
        return new T.MeshStandardMaterial(Object.assign({}, base, { flatShading: true },
          gr[2] && !v.color ? { color: new T.Color().fromArray(gr[2]) } : {}));
      });
      var mm = new T.Mesh(geo, mats);
      place(mm, v);
      return mm;
    } else if (v.kind === "box") {
      geo = new T.BoxGeometry(v.size[0], v.size[1], v.size[2]);
    } else if (v.kind === "cylinder") {
      geo = new T.CylinderGeometry(v.size[0], v.size[0], v.size[1], 32);
      geo.rotateX(Math.PI / 2);  // three.js's cylinders stand along y, URDF's along z
    } else {
      geo = new T.SphereGeometry(v.size[0], 32, 16);
    }
    var m = new T.Mesh(geo, new T.MeshStandardMaterial(base));
    place(m, v);
    return m;
  }

  // --- bodies ------------------------------------------------------------------------------
  var groups = {};
  var coms = {};
  var order = [];
  scene.bodies.forEach(function (b, i) {
    var g = new T.Group();
    g.name = b.name;
    groups[b.name] = g;
    order.push(b.name);
    world.add(g);
    var colour = new T.Color(b.color);
    // the centre of mass with the principal axes: the equivalent shape is drawn there
    var c = new T.Group();
    place(c, b.shape);
    g.add(c);
    coms[b.name] = c;
    var mat = new T.MeshStandardMaterial({ color: colour, roughness: 0.6, metalness: 0.05 });
    if (b.visuals.length) {
      b.visuals.forEach(function (v) { g.add(visual(v, colour)); });
    } else if (b.shape.kind === "box") {
      c.add(new T.Mesh(new T.BoxGeometry(b.shape.size[0], b.shape.size[1], b.shape.size[2]), mat));
    } else if (b.shape.kind === "ellipsoid" || b.shape.kind === "sphere") {
      var s = new T.Mesh(new T.SphereGeometry(1, 32, 16), mat);
      s.scale.set(b.shape.size[0] / 2, b.shape.size[1] / 2, b.shape.size[2] / 2);
      c.add(s);
    }
    g.add(triad(0.07 * L, 1));
  });
  // joint frames: fixed in the parent's frame (or the inertial frame)
  scene.bodies.forEach(function (b) {
    var j = triad(0.045 * L, 0.55);
    place(j, b.joint);
    (b.parent === "world" ? world : groups[b.parent]).add(j);
  });
  world.add(triad(0.08 * L, 0.7));
  scene.world_visuals.forEach(function (v) { world.add(visual(v, new T.Color(0x9a9a9a))); });

  // spring-dampers: one line each between their points
  var springGeo = new T.BufferGeometry();
  var springPos = new Float32Array(6 * Math.max(scene.springs.length, 1));
  springGeo.setAttribute("position", new T.BufferAttribute(springPos, 3));
  var springs = new T.LineSegments(springGeo, new T.LineBasicMaterial({ color: 0x8e24aa }));
  springs.frustumCulled = false;
  if (scene.springs.length) world.add(springs);
  var pa = new T.Vector3();

  // closing joints (a closed system's): each body's origin to its point, the two points
  // joined (of zero length where the loop is closed), and a marker at the joint
  var closing = scene.closing || [];
  var closeGeo = new T.BufferGeometry();
  var closePos = new Float32Array(18 * Math.max(closing.length, 1));
  closeGeo.setAttribute("position", new T.BufferAttribute(closePos, 3));
  var closeLines = new T.LineSegments(closeGeo, new T.LineBasicMaterial({ color: 0xd62728 }));
  closeLines.frustumCulled = false;
  var closeMarks = closing.map(function () {
    var m = new T.Mesh(new T.SphereGeometry(0.018 * L, 16, 8),
                       new T.MeshBasicMaterial({ color: 0xd62728 }));
    world.add(m);
    return m;
  });
  if (closing.length) world.add(closeLines);
  var ZERO = [0, 0, 0];

  // elastic bodies: their nodes joined in order (the deflected line, moving with the modes)
  var elastic = [];
  (scene.elastic || []).forEach(function (e) {
    for (var k = 0; k + 1 < e.nodes.length; k++) elastic.push([e.nodes[k], e.nodes[k + 1]]);
  });
  var elasticGeo = new T.BufferGeometry();
  var elasticPos = new Float32Array(6 * Math.max(elastic.length, 1));
  elasticGeo.setAttribute("position", new T.BufferAttribute(elasticPos, 3));
  var elasticLines = new T.LineSegments(elasticGeo,
                                        new T.LineBasicMaterial({ color: 0x1f3b73 }));
  elasticLines.frustumCulled = false;
  if (elastic.length) world.add(elasticLines);

  function springPoint(body, p, out, k) {
    pa.fromArray(p);
    if (body !== "world") pa.applyMatrix4(groups[body].matrixWorld);
    out[k] = pa.x; out[k + 1] = pa.y; out[k + 2] = pa.z;
  }

  // --- time --------------------------------------------------------------------------------
  var qa = new T.Quaternion();
  var qb = new T.Quaternion();
  var current = times[0];

  function frameAt(t) {  // k with times[k] <= t < times[k+1], and the fraction between them
    if (!(t > times[0])) return [0, 0];
    if (t >= times[nf - 1]) return [nf - 1, 0];
    var lo = 0, hi = nf - 1;
    while (hi - lo > 1) {
      var mid = (lo + hi) >> 1;
      if (times[mid] <= t) lo = mid; else hi = mid;
    }
    return [lo, (t - times[lo]) / (times[hi] - times[lo])];
  }

  function setTime(t) {
    var f = frameAt(t);
    var k = f[0], a = f[1];
    current = Math.min(Math.max(t, times[0]), times[nf - 1]);
    for (var i = 0; i < nb; i++) {
      var o = 7 * (k * nb + i);
      var g = groups[order[i]];
      g.position.set(poses[o], poses[o + 1], poses[o + 2]);
      g.quaternion.set(poses[o + 3], poses[o + 4], poses[o + 5], poses[o + 6]);
      if (a > 0) {
        var o2 = o + 7 * nb;
        g.position.lerp(pa.set(poses[o2], poses[o2 + 1], poses[o2 + 2]), a);
        qb.set(poses[o2 + 3], poses[o2 + 4], poses[o2 + 5], poses[o2 + 6]);
        qa.copy(g.quaternion).slerp(qb, a);
        g.quaternion.copy(qa);
      }
    }
    world.updateMatrixWorld(true);
    scene.springs.forEach(function (s, n) {
      springPoint(s.body_a, s.point_a, springPos, 6 * n);
      springPoint(s.body_b, s.point_b, springPos, 6 * n + 3);
    });
    springGeo.attributes.position.needsUpdate = true;
    elastic.forEach(function (e, n) {
      springPoint(e[0], ZERO, elasticPos, 6 * n);
      springPoint(e[1], ZERO, elasticPos, 6 * n + 3);
    });
    elasticGeo.attributes.position.needsUpdate = true;
    closing.forEach(function (c, n) {
      var o = 18 * n;
      springPoint(c.body_a, ZERO, closePos, o);
      springPoint(c.body_a, c.point_a, closePos, o + 3);
      springPoint(c.body_b, ZERO, closePos, o + 6);
      springPoint(c.body_b, c.point_b, closePos, o + 9);
      springPoint(c.body_a, c.point_a, closePos, o + 12);
      springPoint(c.body_b, c.point_b, closePos, o + 15);
      closeMarks[n].position.set(closePos[o + 3], closePos[o + 4], closePos[o + 5]);
    });
    closeGeo.attributes.position.needsUpdate = true;
    slider.value = String(current);
    label.textContent = "t = " + current.toFixed(3) + " s";
    dirty = true;
  }

  // --- controls of the page ----------------------------------------------------------------
  var slider = root.querySelector(".jv-slider");
  var label = root.querySelector(".jv-time");
  var button = root.querySelector(".jv-play");
  var speedBox = root.querySelector(".jv-speed");
  slider.min = String(times[0]);
  slider.max = String(times[nf - 1]);
  slider.step = "any";
  var playing = false;
  var dirty = true;
  var last = null;

  function setPlaying(on) {
    playing = on && nf > 1;
    button.textContent = playing ? "❚❚ pause" : "▶ play";
    last = null;
  }
  button.addEventListener("click", function () {
    if (!playing && current >= times[nf - 1]) setTime(times[0]);
    setPlaying(!playing);
  });
  slider.addEventListener("input", function () {
    setPlaying(false);
    setTime(parseFloat(slider.value));
  });
  controls.addEventListener("change", function () { dirty = true; });

  function resize() {
    var w = canvasBox.clientWidth || 1, h = canvasBox.clientHeight || 1;
    renderer.setSize(w, h, false);
    camera.aspect = w / h;
    camera.updateProjectionMatrix();
    dirty = true;
  }
  if (window.ResizeObserver) new ResizeObserver(resize).observe(canvasBox);
  window.addEventListener("resize", resize);

  function loop(now) {
    if (playing) {
      if (last !== null) {
        var t = current + (now - last) / 1000 * parseFloat(speedBox.value);
        if (t > times[nf - 1]) t = times[0];  // loops
        setTime(t);
      }
      last = now;
    }
    if (dirty) {
      renderer.render(world, camera);
      dirty = false;
    }
    requestAnimationFrame(loop);
  }

  // #t=1.5 (paused there) or #t=1.5&play
  var hash = {};
  location.hash.replace(/^#/, "").split("&").forEach(function (kv) {
    var p = kv.split("=");
    if (p[0]) hash[p[0]] = p.length > 1 ? decodeURIComponent(p[1]) : "";
  });
  var t0 = hash.t !== undefined && isFinite(parseFloat(hash.t)) ? parseFloat(hash.t) : times[0];
  resize();
  setTime(t0);
  setPlaying(hash.t === undefined || "play" in hash);
  renderer.render(world, camera);
  dirty = false;
  requestAnimationFrame(loop);

  function world3(obj) {
    var v = new T.Vector3();
    obj.getWorldPosition(v);
    return [v.x, v.y, v.z];
  }

  function body(name) {
    if (!(name in groups)) throw new Error("no body named " + JSON.stringify(name));
    return groups[name];
  }

  window.jourdainViewer = {
    times: times,
    bodies: order.slice(),
    three: T,
    renderer: renderer,
    setTime: function (t) { setPlaying(false); setTime(t); renderer.render(world, camera);
                            dirty = false; },
    time: function () { return current; },
    play: function () { setPlaying(true); },
    pause: function () { setPlaying(false); },
    bodyPosition: function (name, t) { this.setTime(t); return world3(body(name)); },
    comPosition: function (name, t) { body(name); this.setTime(t); return world3(coms[name]); },
    bodyQuaternion: function (name, t) {
      this.setTime(t);
      var q = new T.Quaternion();
      body(name).getWorldQuaternion(q);
      return [q.x, q.y, q.z, q.w];
    },
  };
})();
