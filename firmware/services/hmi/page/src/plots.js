// The plots: loop timing histograms and the force over the last seconds, on plain 2-D canvases.
export function drawHistogram(canvas, histogram, unit) {
  const g = canvas.getContext('2d');
  const { width, height } = canvas;
  g.clearRect(0, 0, width, height);
  const counts = histogram.counts;
  const total = counts.reduce((a, b) => a + b, 0);
  // Log scale: the tail is what matters, and it is rare.
  const top = Math.log10(1 + Math.max(...counts, 1));
  const barWidth = (width - 30) / counts.length;
  g.fillStyle = '#6fa8dc';
  counts.forEach((count, i) => {
    const h = (Math.log10(1 + count) / top) * (height - 18);
    g.fillStyle = i === counts.length - 1 ? '#ff6b6b' : '#6fa8dc';
    g.fillRect(25 + i * barWidth, height - 14 - h, Math.max(barWidth - 1, 1), h);
  });
  g.fillStyle = '#a9b4c2';
  g.font = '10px sans-serif';
  g.fillText('0', 25, height - 2);
  g.fillText(`${(counts.length - 1) * histogram.bin_us} ${unit}+`, width - 60, height - 2);
  g.fillText(`n=${total}  max ${histogram.max_us} ${unit}  (log)`, 30, 10);
}

export class ForcePlot {
  constructor(canvas, seconds) {
    this.canvas = canvas;
    this.seconds = seconds;
    this.points = [];
  }

  restart() { this.points = []; }

  add(t, newtons) {
    this.points.push([t, newtons]);
    while (this.points.length > 0 && this.points[0][0] < t - this.seconds) {
      this.points.shift();
    }
    this.draw(t);
  }

  draw(now) {
    const g = this.canvas.getContext('2d');
    const { width, height } = this.canvas;
    g.clearRect(0, 0, width, height);
    const maxN = 6.0;  // the board's 5 N and a little room
    const y = (n) => height - 12 - (n / maxN) * (height - 20);
    g.strokeStyle = '#553333';
    g.beginPath();
    g.moveTo(25, y(5));
    g.lineTo(width, y(5));
    g.stroke();
    g.strokeStyle = '#7bd88f';
    g.beginPath();
    this.points.forEach(([t, n], i) => {
      const x = 25 + ((t - (now - this.seconds)) / this.seconds) * (width - 25);
      if (i === 0) g.moveTo(x, y(n)); else g.lineTo(x, y(n));
    });
    g.stroke();
    g.fillStyle = '#a9b4c2';
    g.font = '10px sans-serif';
    g.fillText('5 N', 2, y(5) + 3);
    g.fillText('0', 2, y(0) + 3);
    g.fillText(`-${this.seconds} s`, 25, height - 1);
    g.fillText('now', width - 22, height - 1);
  }
}
