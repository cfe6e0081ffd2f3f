// Draws the plots of a `tilth ab` report as inline SVG from the numbers embedded in the
// page (script#ab-data), with no library and no network. When done it sets
// body[data-rendered] to the number of plots drawn ("error" and a message on failure),
// which the tests read from the DOM.
(function () {
  "use strict";
  var SVG = "http://www.w3.org/2000/svg";
  var PALETTE = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b",
                 "#e377c2"];
  var status = document.getElementById("render-status");

  function fail(message) {
    document.body.setAttribute("data-rendered", "error");
    status.textContent = "render error: " + message;
  }
  window.addEventListener("error", function (event) { fail(event.message); });

  function color(index) { return PALETTE[index % PALETTE.length]; }

  function element(name, attributes, parent) {
    var node = document.createElementNS(SVG, name);
    Object.keys(attributes).forEach(function (key) { node.setAttribute(key, attributes[key]); });
    if (parent) parent.appendChild(node);
    return node;
  }

  function text(content, attributes, parent) {
    var node = element("text", attributes, parent);
    node.textContent = content;
    return node;
  }

  // About `count` round tick values covering [low, high].
  function ticks(low, high, count) {
    var step = Math.pow(10, Math.floor(Math.log10((high - low) / count)));
    var error = (high - low) / count / step;
    if (error >= 7) step *= 10; else if (error >= 3) step *= 5; else if (error >= 1.5) step *= 2;
    var values = [];
    for (var value = Math.ceil(low / step) * step; value <= high + step * 1e-9; value += step) {
      values.push(Math.abs(value) < step * 1e-9 ? 0 : value);
    }
    return values;
  }

  function extent(values, pad) {
    var low = Math.min.apply(null, values), high = Math.max.apply(null, values);
    if (!(high > low)) { low -= 0.5; high += 0.5; }
    var margin = (high - low) * pad;
    return [low - margin, high + margin];
  }

  // A plot area with axes; returns scale functions and the SVG.
  function frame(figure, xRange, yRange, xLabel, yLabel) {
    var width = 1000, height = 320, left = 84, right = 16, top = 14, bottom = 42;
    var svg = element("svg", {viewBox: "0 0 " + width + " " + height, width: width,
                              height: height, role: "img"});
    figure.appendChild(svg);
    var x = function (v) {
      return left + (v - xRange[0]) / (xRange[1] - xRange[0]) * (width - left - right);
    };
    var y = function (v) {
      return height - bottom - (v - yRange[0]) / (yRange[1] - yRange[0]) * (height - top - bottom);
    };
    var axes = element("g", {"class": "axes"}, svg);
    ticks(xRange[0], xRange[1], 8).forEach(function (v) {
      element("line", {x1: x(v), x2: x(v), y1: top, y2: height - bottom, "class": "grid"}, axes);
      text(+v.toPrecision(6), {x: x(v), y: height - bottom + 16, "text-anchor": "middle"}, axes);
    });
    ticks(yRange[0], yRange[1], 6).forEach(function (v) {
      element("line", {x1: left, x2: width - right, y1: y(v), y2: y(v), "class": "grid"}, axes);
      text(+v.toPrecision(6), {x: left - 6, y: y(v) + 4, "text-anchor": "end"}, axes);
    });
    element("rect", {x: left, y: top, width: width - left - right, height: height - top - bottom,
                     "class": "border"}, axes);
    text(xLabel, {x: (left + width - right) / 2, y: height - 6, "text-anchor": "middle"}, axes);
    text(yLabel, {x: 14, y: (top + height - bottom) / 2, "text-anchor": "middle",
                  transform: "rotate(-90 14 " + (top + height - bottom) / 2 + ")"}, axes);
    return {svg: svg, x: x, y: y, left: left, right: width - right, top: top,
            bottom: height - bottom};
  }

  // Above the plot's SVG.
  function legend(figure, plot, entries) {
    var list = document.createElement("div");
    list.className = "legend";
    entries.forEach(function (entry) {
      var item = document.createElement("span");
      var swatch = document.createElement("i");
      swatch.style.background = entry.color;
      if (entry.dashed) swatch.className = "dashed";
      item.appendChild(swatch);
      item.appendChild(document.createTextNode(entry.label));
      list.appendChild(item);
    });
    figure.insertBefore(list, plot.svg);
  }

  // Polyline segments through the points whose value is a number: an invalid frame
  // breaks the line.
  function lines(plot, times, values, attributes) {
    var group = element("g", attributes, plot.svg);
    var points = [];
    var flush = function () {
      if (points.length > 1) element("polyline", {points: points.join(" ")}, group);
      if (points.length === 1) {
        var p = points[0].split(",");
        element("circle", {cx: p[0], cy: p[1], r: 2.5}, group);
      }
      points = [];
    };
    times.forEach(function (t, i) {
      if (values[i] === null) { flush(); return; }
      points.push(plot.x(t).toFixed(2) + "," + plot.y(values[i]).toFixed(2));
    });
    flush();
    return group;
  }

  function distancePlot(figure, recording) {
    var times = [], values = [];
    recording.series.forEach(function (series) {
      series.t.forEach(function (t, i) {
        times.push(t);
        if (series.d[i] !== null) values.push(series.d[i]);
      });
    });
    recording.truth.t.forEach(function (t, i) {
      times.push(t);
      if (recording.truth.d[i] !== null) values.push(recording.truth.d[i]);
    });
    if (times.length === 0) {
      figure.appendChild(document.createTextNode("no frames"));
      return;
    }
    if (values.length === 0) values = [0];
    var plot = frame(figure, extent(times, 0.02), extent(values, 0.08), "time (s)",
                     "distance (mm)");
    lines(plot, recording.truth.t, recording.truth.d, {"class": "truth"});
    var rows = recording.series.length;
    recording.series.forEach(function (series, v) {
      var group = lines(plot, series.t, series.d, {"class": "series", stroke: color(v),
                                                  fill: color(v)});
      // Frames reported invalid: ticks in a strip of the variant's colour at the bottom.
      series.t.forEach(function (t, i) {
        if (series.d[i] !== null) return;
        var y = plot.bottom - 4 - (rows - 1 - v) * 5;
        element("line", {x1: plot.x(t), x2: plot.x(t), y1: y - 4, y2: y, stroke: color(v),
                         "class": "invalid"}, group);
      });
    });
    var entries = recording.series.map(function (series, v) {
      return {label: series.variant, color: color(v)};
    });
    entries.push({label: "truth", color: "#000", dashed: true});
    legend(figure, plot, entries);
    readout(figure, plot, recording);
  }

  // Shows the nearest frame's values under the pointer.
  function readout(figure, plot, recording) {
    var marker = element("line", {y1: plot.top, y2: plot.bottom, "class": "cursor",
                                  visibility: "hidden"}, plot.svg);
    var label = document.createElement("div");
    label.className = "readout";
    label.textContent = "\u00a0";
    figure.appendChild(label);
    var times = recording.series.length ? recording.series[0].t : recording.truth.t;
    plot.svg.addEventListener("mousemove", function (event) {
      var box = plot.svg.getBoundingClientRect();
      var px = (event.clientX - box.left) * (plot.svg.viewBox.baseVal.width / box.width);
      var best = 0;
      times.forEach(function (t, i) {
        if (Math.abs(plot.x(t) - px) < Math.abs(plot.x(times[best]) - px)) best = i;
      });
      marker.setAttribute("x1", plot.x(times[best]));
      marker.setAttribute("x2", plot.x(times[best]));
      marker.setAttribute("visibility", "visible");
      var parts = ["t " + times[best].toFixed(3) + " s"];
      recording.series.forEach(function (series) {
        var d = series.d[best];
        parts.push(series.variant + " " + (d === null ? "invalid" : d.toFixed(2) + " mm"));
      });
      var truth = recording.truth.d[best];
      if (truth !== null && truth !== undefined) parts.push("truth " + truth.toFixed(2) + " mm");
      label.textContent = parts.join("   ");
    });
  }

  function histogramPlot(figure, histogram, variants) {
    if (!histogram.bins) {
      figure.appendChild(document.createTextNode("no valid frame with a true distance"));
      return;
    }
    var first = histogram.first_edge_mm, width = histogram.width_mm;
    var top = 1;
    variants.forEach(function (name) {
      histogram.counts[name].forEach(function (c) { top = Math.max(top, c); });
    });
    var plot = frame(figure, [first, first + width * histogram.bins], [0, top * 1.08],
                     "error: measured \u2212 true (mm)", "frames");
    var share = width / variants.length;
    variants.forEach(function (name, v) {
      var group = element("g", {fill: color(v), "class": "bars"}, plot.svg);
      histogram.counts[name].forEach(function (count, bin) {
        if (count === 0) return;
        var x0 = plot.x(first + bin * width + v * share), x1 = plot.x(first + bin * width + (v + 1) * share);
        var bar = element("rect", {x: x0, y: plot.y(count), width: Math.max(x1 - x0 - 0.5, 0.5),
                                   height: plot.y(0) - plot.y(count)}, group);
        var edge = first + bin * width;
        element("title", {}, bar).textContent = name + ": " + count + " frames in [" +
            +edge.toPrecision(6) + ", " + +(edge + width).toPrecision(6) + ") mm";
      });
    });
    legend(figure, plot, variants.map(function (name, v) { return {label: name, color: color(v)}; }));
  }

  // A click on an overlay shows it at its own resolution times a zoom (wheel, + and -),
  // over the page; Esc or a click outside the image closes it.
  function zoomViewer() {
    var viewer = document.createElement("div");
    viewer.className = "zoom";
    viewer.hidden = true;
    var bar = document.createElement("div");
    bar.className = "zoom-bar";
    var caption = document.createElement("span");
    var scroller = document.createElement("div");
    scroller.className = "zoom-area";
    var image = document.createElement("img");
    scroller.appendChild(image);
    var scale = 1;
    function show() {
      image.style.width = image.naturalWidth * scale + "px";
      caption.textContent = image.alt + " \u2014 " + image.naturalWidth + "\u00d7" +
          image.naturalHeight + " px, zoom " + scale + "\u00d7";
    }
    function zoom(factor) {
      scale = Math.min(16, Math.max(1, scale * factor));
      show();
    }
    function close() { viewer.hidden = true; }
    [["\u2212", function () { zoom(0.5); }], ["+", function () { zoom(2); }],
     ["\u00d7", close]].forEach(function (entry) {
      var button = document.createElement("button");
      button.textContent = entry[0];
      button.addEventListener("click", entry[1]);
      bar.appendChild(button);
    });
    bar.appendChild(caption);
    viewer.appendChild(bar);
    viewer.appendChild(scroller);
    document.body.appendChild(viewer);
    scroller.addEventListener("wheel", function (event) {
      event.preventDefault();
      zoom(event.deltaY < 0 ? 2 : 0.5);
    });
    scroller.addEventListener("click", function (event) { if (event.target === scroller) close(); });
    document.addEventListener("keydown", function (event) {
      if (viewer.hidden) return;
      if (event.key === "Escape") close();
      if (event.key === "+" || event.key === "=") zoom(2);
      if (event.key === "-") zoom(0.5);
    });
    document.querySelectorAll(".overlays img").forEach(function (thumbnail) {
      thumbnail.addEventListener("click", function () {
        image.onload = show;
        image.alt = thumbnail.alt;
        image.src = thumbnail.src;
        scale = 2;
        viewer.hidden = false;
        if (image.complete) show();
      });
    });
  }

  try {
    zoomViewer();
    var data = JSON.parse(document.getElementById("ab-data").textContent);
    var drawn = 0;
    document.querySelectorAll("figure.plot").forEach(function (figure) {
      var kind = figure.getAttribute("data-plot");
      if (kind === "distance") {
        distancePlot(figure, data.recordings[+figure.getAttribute("data-recording")]);
      } else if (kind === "histogram") {
        histogramPlot(figure, data.histogram, data.variants);
      } else {
        throw new Error("unknown plot kind " + kind);
      }
      drawn += 1;
    });
    if (document.body.getAttribute("data-rendered") !== "error") {
      document.body.setAttribute("data-rendered", String(drawn));
      status.textContent = "rendered " + drawn + " plots";
    }
  } catch (failure) {
    fail(failure && failure.message ? failure.message : String(failure));
  }
})();
