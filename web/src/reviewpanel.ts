// The patch review panel: the target (the fill so far with the best candidate pasted, around the target
// patch) and one tile per cluster of candidates (its best member, enlarged, with its verdict and the number
// of near-identical members). Clicking a tile accepts that candidate; "place by hand" lets the next pick in
// the ray image choose the source patch's centre.
import { precision } from './api';
import { ClusterGroup, PendingReview, groupCandidates, patchRect, verdictText } from './review';

export class ReviewPanel {
  onAccept: (candidate: number) => void = () => {};

  constructor(
    private root: HTMLElement,
    private target: HTMLCanvasElement,
    private tiles: HTMLElement,
    private caption: HTMLElement,
  ) {}

  hide() {
    this.root.hidden = true;
    this.tiles.replaceChildren();
  }

  // Draws the review: `canvas` is the fill so far (candidates are cut from it), `tentative` the same with the
  // best candidate pasted (the target view).
  show(pending: PendingReview, canvas: HTMLImageElement, tentative: HTMLImageElement) {
    this.root.hidden = false;
    const { review } = pending;
    const radius = review.patch_radius;
    const groups = groupCandidates(pending);
    this.caption.textContent = `review point ${review.review_point + 1} (fill step ${review.iteration}): no candidate passes at row ${review.target[0]}, column ${review.target[1]}. ${review.candidates.length} candidates in ${groups.length} groups; ${pending.decisions.length} decided so far. Click a group to accept its best patch, or place one by hand.`;
    // The target: a window 5 patches wide around it, the target patch outlined.
    const context = this.target.getContext('2d')!;
    const window = 5 * (2 * radius + 1);
    const zoom = Math.max(1, Math.floor(this.target.width / window));
    const x0 = review.target[1] - Math.floor(window / 2),
      y0 = review.target[0] - Math.floor(window / 2);
    context.imageSmoothingEnabled = false;
    context.fillStyle = '#000';
    context.fillRect(0, 0, this.target.width, this.target.height);
    context.drawImage(tentative, x0, y0, window, window, 0, 0, window * zoom, window * zoom);
    const rect = patchRect(review.target, radius);
    context.strokeStyle = '#ff0';
    context.lineWidth = 2;
    context.strokeRect((rect.x - x0) * zoom, (rect.y - y0) * zoom, rect.size * zoom, rect.size * zoom);
    this.tiles.replaceChildren(...groups.map((group) => this.tile(group, canvas, radius)));
  }

  private tile(group: ClusterGroup, canvas: HTMLImageElement, radius: number): HTMLElement {
    const button = document.createElement('button');
    button.className = 'review-tile';
    button.dataset.candidate = String(group.representative.index);
    const size = 2 * radius + 1,
      zoom = 6;
    const picture = document.createElement('canvas');
    picture.width = picture.height = size * zoom;
    const context = picture.getContext('2d')!;
    context.imageSmoothingEnabled = false;
    const rect = patchRect(group.representative.source, radius);
    context.drawImage(canvas, rect.x, rect.y, size, size, 0, 0, size * zoom, size * zoom);
    const label = document.createElement('span');
    label.textContent = `#${group.rank} ×${group.members.length}`;
    button.title = `candidate ${group.representative.index} at row ${group.representative.source[0]}, column ${group.representative.source[1]}; difference ${precision(group.representative.difference, 3)}; ${verdictText(group.representative)}; ${group.members.length} similar`;
    button.append(picture, label);
    button.addEventListener('click', () => this.onAccept(group.representative.index));
    return button;
  }
}
